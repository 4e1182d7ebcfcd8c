#include "track/ball_segmenter.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "track/mask_components.h"

namespace bouncefit {

namespace {

// A box and a centroid in work pixels (a step of s from the planes' origin ox, oy) in frame pixels.
cv::Rect2f ToFrame(const cv::Rect& box, float s, float ox, float oy) {
  return cv::Rect2f(ox + box.x * s, oy + box.y * s, box.width * s, box.height * s);
}
cv::Point2f ToFrame(double cx, double cy, float s, float ox, float oy) {
  return cv::Point2f(ox + (static_cast<float>(cx) + 0.5f) * s - 0.5f, oy + (static_cast<float>(cy) + 0.5f) * s - 0.5f);
}

// The pieces that lines of another colour cut a ball into, as one blob each ball (within the
// size limits; their shape is JoinSplitBall's): appended to *blobs, their labels' entries in
// *keep set to it, the lines between them set in *mask.
void JoinPieces(const cv::Mat& labels, const cv::Mat& stats, cv::Rect box, int n, const SegmenterParams& params,
                float s, float ox, float oy, cv::Mat* mask, std::vector<int>* keep, std::vector<Blob>* blobs) {
  const double gap = params.join_gap_px / s;  // work pixels
  for (const JoinedPieces& g : JoinSplitBall(labels, stats, box, mask->size(), n, gap, params.joined)) {
    const double side_min = std::min(g.box.width, g.box.height) * s, side_max = std::max(g.box.width, g.box.height) * s;
    if (side_min < params.min_box_px || side_max > params.max_box_px || side_max / side_min > params.max_aspect)
      continue;
    Blob b;
    b.box = ToFrame(g.box, s, ox, oy);
    const cv::Rect2f in(params.join_inside);
    if (!in.empty() && (b.box.x <= in.x || b.box.y <= in.y || b.box.br().x >= in.br().x || b.box.br().y >= in.br().y))
      continue;
    b.centroid = ToFrame(g.centroid.x, g.centroid.y, s, ox, oy);
    b.pixels = static_cast<int>(g.area * s * s);
    b.fill = static_cast<float>(g.area / (static_cast<double>(g.box.width) * g.box.height));
    b.touches_edge = g.touches_edge;
    b.joined = true;
    for (int l : g.labels) (*keep)[static_cast<size_t>(l)] = static_cast<int>(blobs->size());
    (*mask)(g.box).setTo(255, g.region);
    blobs->push_back(b);
  }
}

}  // namespace

std::vector<Blob> SegmentBlobs(const YccPlanes& planes, const ColorModel& color,
                               const SegmenterParams& params, cv::Mat* mask) {
  std::vector<Blob> blobs;
  const int w = planes.y.cols, h = planes.y.rows;
  mask->create(h, w, CV_8U);
  if (w == 0 || h == 0) return blobs;
  cv::Mat dist(h, w, CV_32F);
  for (int j = 0; j < h; ++j) {
    const float* py = planes.y.ptr<float>(j);
    const float* pu = planes.u.ptr<float>(j);
    const float* pv = planes.v.ptr<float>(j);
    float* pd = dist.ptr<float>(j);
    color.DistanceRow(py, pu, pv, w, pd, mask->ptr<uint8_t>(j));
  }
  cv::Mat labels, stats, centroids;
  cv::Rect box;  // of the matching pixels; labels are the box's
  const int n = MaskComponents(*mask, &labels, &stats, &centroids, &box);
  if (n <= 1) return blobs;
  const float s = static_cast<float>(planes.step);
  const float ox = static_cast<float>(planes.rect.x), oy = static_cast<float>(planes.rect.y);
  std::vector<int> keep(n, -1);
  if (params.join_gap_px > 0 && n > 2) JoinPieces(labels, stats, box, n, params, s, ox, oy, mask, &keep, &blobs);
  for (int k = 1; k < n; ++k) {
    if (keep[k] >= 0) continue;  // a piece of a joined blob
    const int bx = stats.at<int>(k, cv::CC_STAT_LEFT), by = stats.at<int>(k, cv::CC_STAT_TOP);
    const int bw = stats.at<int>(k, cv::CC_STAT_WIDTH), bh = stats.at<int>(k, cv::CC_STAT_HEIGHT);
    const int area = stats.at<int>(k, cv::CC_STAT_AREA);
    const double side_min = std::min(bw, bh) * s, side_max = std::max(bw, bh) * s;
    if (side_min < params.min_box_px || side_max > params.max_box_px) continue;
    const bool edge = bx == 0 || by == 0 || bx + bw == w || by + bh == h;
    const double fill = static_cast<double>(area) / (static_cast<double>(bw) * bh);
    // Shape limits only for blobs seen whole: a ball cut by the border is neither.
    if (!edge && (side_max / side_min > params.max_aspect || fill > params.max_fill ||
                  fill < params.min_fill))
      continue;
    Blob b;
    b.box = ToFrame(cv::Rect(bx, by, bw, bh), s, ox, oy);
    b.centroid = ToFrame(centroids.at<double>(k, 0), centroids.at<double>(k, 1), s, ox, oy);
    b.pixels = static_cast<int>(area * s * s);
    b.touches_edge = edge;
    b.fill = static_cast<float>(fill);
    keep[k] = static_cast<int>(blobs.size());
    blobs.push_back(b);
  }
  if (blobs.empty()) return blobs;
  // Mean colour of each kept blob.
  std::vector<double> sd(blobs.size(), 0), su(blobs.size(), 0), sv(blobs.size(), 0);
  std::vector<int> cnt(blobs.size(), 0);
  for (int j = box.y; j < box.y + box.height; ++j) {
    const int* pl = labels.ptr<int>(j - box.y);
    const float* py = planes.y.ptr<float>(j);
    const float* pu = planes.u.ptr<float>(j);
    const float* pv = planes.v.ptr<float>(j);
    const float* pd = dist.ptr<float>(j);
    for (int i = box.x; i < box.x + box.width; ++i) {
      const int label = pl[i - box.x];
      const int k = label > 0 ? keep[label] : -1;
      if (k < 0) continue;
      const float yy = std::max(py[i], static_cast<float>(color.params().luma_floor));
      sd[k] += pd[i];
      su[k] += pu[i] / yy;
      sv[k] += pv[i] / yy;
      ++cnt[k];
    }
  }
  for (size_t k = 0; k < blobs.size(); ++k) {
    const double c = std::max(cnt[k], 1);
    blobs[k].mean_distance = static_cast<float>(sd[k] / c);
    blobs[k].nu = static_cast<float>(su[k] / c);
    blobs[k].nv = static_cast<float>(sv[k] / c);
  }
  return blobs;
}

}  // namespace bouncefit
