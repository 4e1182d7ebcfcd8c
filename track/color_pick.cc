#include "track/color_pick.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "track/ycc_planes.h"

namespace bouncefit {

namespace {

double Median(std::vector<float>& v) {
  if (v.empty()) return 0;
  auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Regions larger than this are previewed at half resolution, so a drag stays fluid on 1080p.
constexpr double kFullResolutionPixels = 640.0 * 480.0;

}  // namespace

PickedColor PickColor(const Frame& frame, double x_px, double y_px, const ColorModelParams& params,
                      double blur_sigma_px) {
  const cv::Size size = FramePixelSize(frame);
  const int x = static_cast<int>(std::lround(x_px));
  const int y = static_cast<int>(std::lround(y_px));
  if (x < 0 || y < 0 || x >= size.width || y >= size.height) {
    throw std::invalid_argument(
        fmt::format("pick point {:.0f},{:.0f} is outside the {}x{} px frame", x_px, y_px, size.width, size.height));
  }
  YccPlanes p;
  ExtractYcc(frame, cv::Rect(x - 5, y - 5, 11, 11), 1, blur_sigma_px, &p);
  std::vector<float> nu, nv;
  const int cx = x - p.rect.x, cy = y - p.rect.y;
  for (int j = std::max(0, cy - 2); j <= std::min(p.y.rows - 1, cy + 2); ++j)
    for (int i = std::max(0, cx - 2); i <= std::min(p.y.cols - 1, cx + 2); ++i) {
      const float yy = std::max(p.y.at<float>(j, i), static_cast<float>(params.luma_floor));
      nu.push_back(p.u.at<float>(j, i) / yy);
      nv.push_back(p.v.at<float>(j, i) / yy);
    }
  PickedColor out;
  out.color = ColorModel(Median(nu), Median(nv), params);
  out.ball_luma = p.y.at<float>(std::clamp(cy, 0, p.y.rows - 1), std::clamp(cx, 0, p.y.cols - 1));
  // The surroundings: a 121 px square around the pick, mostly background.
  YccPlanes around;
  ExtractYcc(frame, cv::Rect(x - 60, y - 60, 121, 121) & cv::Rect({}, size), 1, 0, &around);
  std::vector<float> ys(around.y.begin<float>(), around.y.end<float>());
  out.surround_luma = Median(ys);
  if (std::hypot(out.color.nu(), out.color.nv()) < kGreyChroma) {
    out.grey = true;
    out.polarity = out.ball_luma >= out.surround_luma ? +1 : -1;
  }
  return out;
}

int ChromaHistogram::BinOf(double value) {
  const int b = static_cast<int>(std::floor((value + kRange) / (2 * kRange) * kBins));
  return std::clamp(b, 0, kBins - 1);
}

PickPreview ComputePickPreview(const Frame& frame, cv::Point2d click, cv::Rect roi,
                               const ColorModelParams& color, const SegmenterParams& segment,
                               double blur_sigma_px) {
  PickPreview p;
  const cv::Rect full({}, FramePixelSize(frame));
  p.roi = roi.area() > 0 ? roi & full : full;
  if (p.roi.width < 8 || p.roi.height < 8)
    throw std::invalid_argument("the region of interest must be at least 8x8 px inside the frame");
  p.click = click;
  p.picked = PickColor(frame, click.x, click.y, color, blur_sigma_px);
  p.step = p.roi.area() > kFullResolutionPixels ? 2 : 1;
  YccPlanes planes;
  ExtractYcc(frame, p.roi, p.step, blur_sigma_px / p.step, &planes);

  const ColorModel& model = p.picked.color;
  const double tol = model.tolerance();
  p.cb_low = model.nu() - tol, p.cb_high = model.nu() + tol;
  p.cr_low = model.nv() - tol, p.cr_high = model.nv() + tol;
  if (p.picked.grey) {
    p.mask = cv::Mat::zeros(planes.y.size(), CV_8U);  // brightness has no colour mask
  } else {
    p.blobs = SegmentBlobs(planes, model, segment, &p.mask);
  }
  const float floor = static_cast<float>(color.luma_floor), dark = static_cast<float>(color.min_luma);
  int bright = 0, matching = 0;
  for (int j = 0; j < planes.y.rows; ++j) {
    const float* py = planes.y.ptr<float>(j);
    const float* pu = planes.u.ptr<float>(j);
    const float* pv = planes.v.ptr<float>(j);
    const uint8_t* pm = p.mask.ptr<uint8_t>(j);
    for (int i = 0; i < planes.y.cols; ++i) {
      if (py[i] < dark) continue;
      const float inv = 1.0f / std::max(py[i], floor);
      const int bu = ChromaHistogram::BinOf(pu[i] * inv), bv = ChromaHistogram::BinOf(pv[i] * inv);
      ++p.cb.all[bu], ++p.cr.all[bv], ++bright;
      if (pm[i]) ++p.cb.matching[bu], ++p.cr.matching[bv], ++matching;
    }
  }
  p.match_share = static_cast<double>(matching) / std::max(1, planes.y.rows * planes.y.cols);
  // The ball's blob: the one whose box holds the click, else the nearest within its size.
  double best = 1e18;
  for (size_t k = 0; k < p.blobs.size(); ++k) {
    const Blob& b = p.blobs[k];
    const double d = std::hypot(b.centroid.x - click.x, b.centroid.y - click.y);
    const bool inside = b.box.contains(cv::Point2f(static_cast<float>(click.x), static_cast<float>(click.y)));
    const double reach = std::max(b.box.width, b.box.height);
    if ((inside || d < reach) && d < best) best = d, p.ball_blob = static_cast<int>(k);
  }
  return p;
}

std::string DescribePick(const PickPreview& p) {
  if (p.picked.grey) {
    return fmt::format("nearly grey (chroma/luma {:.2f}): its brightness is tracked, {} than its "
                       "surroundings (luma {:.0f} vs {:.0f})",
                       std::hypot(p.picked.color.nu(), p.picked.color.nv()),
                       p.picked.polarity > 0 ? "brighter" : "darker", p.picked.ball_luma, p.picked.surround_luma);
  }
  std::string blob = "no ball-sized blob at the click";
  if (p.ball_blob >= 0) {
    const Blob& b = p.blobs[static_cast<size_t>(p.ball_blob)];
    blob = fmt::format("ball blob {:.0f}x{:.0f} px at {:.0f},{:.0f}", b.box.width, b.box.height, b.centroid.x,
                       b.centroid.y);
  }
  return fmt::format("Cb/Y {:.2f}..{:.2f}, Cr/Y {:.2f}..{:.2f}; {:.1f}% of the region matches; {} blob{}; {}", p.cb_low,
                     p.cb_high, p.cr_low, p.cr_high, 100 * p.match_share, p.blobs.size(),
                     p.blobs.size() == 1 ? "" : "s", blob);
}

}  // namespace bouncefit
