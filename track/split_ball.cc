#include "track/split_ball.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "track/mask_components.h"

namespace bouncefit {

std::vector<JoinedPieces> JoinSplitBall(const cv::Mat& labels, const cv::Mat& stats, cv::Rect box, cv::Size mask_size,
                                        int n, double gap_px, const SplitBallShape& shape) {
  std::vector<JoinedPieces> out;
  if (n < 3 || !(gap_px >= 1) || labels.empty()) return out;
  // Closing with a disc of radius k bridges gaps up to 2k wide; on cells of f pixels, a disc
  // of k / f cells (about 3: a round enough disc, cheap whatever the gap).
  const int k = static_cast<int>(std::ceil(0.5 * gap_px));
  const int f = std::max(1, k / 3);
  const int kc = (k + f - 1) / f;
  // The cells in a margin of empty ones: the closing sees nothing beyond the box, as the mask
  // has nothing there.
  const int pad = kc + 1;
  const int cols = (labels.cols + f - 1) / f, rows = (labels.rows + f - 1) / f;
  cv::Mat cells = cv::Mat::zeros(rows + 2 * pad, cols + 2 * pad, CV_8U);
  for (int j = 0; j < labels.rows; ++j) {
    const int* l = labels.ptr<int>(j);
    uint8_t* c = cells.ptr<uint8_t>(pad + j / f) + pad;
    for (int i = 0; i < labels.cols; ++i)
      if (l[i] > 0) c[i / f] = 255;
  }
  cv::Mat closed;
  cv::morphologyEx(cells, closed, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * kc + 1, 2 * kc + 1}));
  cv::Mat region_labels, region_stats, region_centroids;
  const int m = ComponentsWithStats(closed, &region_labels, &region_stats, &region_centroids);
  // Which closed region each piece lies in; how many pieces and piece pixels each holds.
  std::vector<int> region_of(static_cast<size_t>(n), 0), pieces(static_cast<size_t>(m), 0);
  std::vector<int64_t> piece_pixels(static_cast<size_t>(m), 0), largest(static_cast<size_t>(m), 0);
  for (int l = 1; l < n; ++l) {
    // A piece's first row's leftmost pixel: its cell is in the piece's region.
    const int x = stats.at<int>(l, cv::CC_STAT_LEFT) - box.x, y = stats.at<int>(l, cv::CC_STAT_TOP) - box.y;
    const int* row = labels.ptr<int>(y);
    int i = x;
    while (row[i] != l) ++i;
    const int r = region_labels.at<int>(pad + y / f, pad + i / f);
    region_of[static_cast<size_t>(l)] = r;
    ++pieces[static_cast<size_t>(r)];
    const int64_t area = stats.at<int>(l, cv::CC_STAT_AREA);
    piece_pixels[static_cast<size_t>(r)] += area;
    largest[static_cast<size_t>(r)] = std::max(largest[static_cast<size_t>(r)], area);
  }
  const double cell_area = static_cast<double>(f) * f;
  for (int r = 1; r < m; ++r) {
    if (pieces[static_cast<size_t>(r)] < 2) continue;
    // One piece nearly all of it: the ball whole, specks or a reflection beside it.
    if (largest[static_cast<size_t>(r)] > shape.max_largest_piece * piece_pixels[static_cast<size_t>(r)]) continue;
    JoinedPieces g;
    for (int l = 1; l < n; ++l) {
      if (region_of[static_cast<size_t>(l)] != r) continue;
      g.labels.push_back(l);
      const cv::Rect piece(stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
                           stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT));
      g.box = g.box.empty() ? piece : (g.box | piece);
    }
    g.touches_edge =
        g.box.x <= 0 || g.box.y <= 0 || g.box.br().x >= mask_size.width || g.box.br().y >= mask_size.height;
    // Its outline on the cells, holes filled: a ball's colour may miss its shaded middle,
    // and what is round is its outline.
    const cv::Rect cb(region_stats.at<int>(r, cv::CC_STAT_LEFT), region_stats.at<int>(r, cv::CC_STAT_TOP),
                      region_stats.at<int>(r, cv::CC_STAT_WIDTH), region_stats.at<int>(r, cv::CC_STAT_HEIGHT));
    cv::Mat filled;
    cv::compare(region_labels(cb), r, filled, cv::CMP_EQ);
    std::vector<std::vector<cv::Point>> outline;
    cv::findContours(filled, outline, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    if (outline.size() != 1) continue;
    cv::drawContours(filled, outline, 0, 255, cv::FILLED);
    const cv::Moments mo = cv::moments(filled, true);
    const double cells_area = mo.m00;
    if (piece_pixels[static_cast<size_t>(r)] < shape.min_piece_share * cells_area * cell_area) continue;
    const double shorter = std::min(cb.width, cb.height), longer = std::max(cb.width, cb.height);
    const double stadium = shorter * (longer - shorter) + 0.25 * std::numbers::pi * shorter * shorter;
    const double roundness = cells_area / stadium;
    if (roundness < shape.min_roundness || roundness > shape.max_roundness) continue;
    std::vector<cv::Point> hull;
    cv::convexHull(outline[0], hull);
    const double hull_area = cv::contourArea(hull);
    if (hull_area <= 0 || cv::contourArea(outline[0]) < shape.min_solidity * hull_area) continue;
    // Back on the pixels: cell (cx, cy) covers pixels f cx .. f cx + f - 1 of the box.
    g.centroid = {box.x + (cb.x + mo.m10 / mo.m00 - pad + 0.5) * f - 0.5,
                  box.y + (cb.y + mo.m01 / mo.m00 - pad + 0.5) * f - 0.5};
    g.area = static_cast<int>(std::lround(cells_area * cell_area));
    g.region.create(g.box.size(), CV_8U);
    for (int j = 0; j < g.box.height; ++j) {
      const uint8_t* c = filled.ptr<uint8_t>(pad + (g.box.y - box.y + j) / f - cb.y);
      uint8_t* o = g.region.ptr<uint8_t>(j);
      for (int i = 0; i < g.box.width; ++i) o[i] = c[pad + (g.box.x - box.x + i) / f - cb.x];
    }
    out.push_back(std::move(g));
  }
  return out;
}

}  // namespace bouncefit
