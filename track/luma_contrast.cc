#include "track/luma_contrast.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "track/shrink.h"

namespace bouncefit {

namespace {
constexpr float kContrastLuma = 128;  // the constant Y of contrast planes
}  // namespace

ColorModel LumaContrast::BallModel(const LumaContrastParams& params, ColorModelParams color) {
  // Matches |u/128 - c/128| <= tol: u in [min_contrast, 2c - min_contrast], and u never
  // exceeds the clamp c, so every pixel at least min_contrast beyond the background matches.
  const double c = params.clamp_luma;
  color.tolerance_rel = std::clamp((c - params.min_contrast_luma) / c, 0.05, 2.0);
  color.tolerance_min = 0;
  color.min_luma = 0;
  color.luma_floor = 1;
  return ColorModel(c / kContrastLuma, 0, color);
}

void LumaContrast::SetFrame(const Frame& frame, double closeup_radius_px) {
  std::swap(previous_, grey_);
  // Luma only (the same BT.601 weights as ExtractYcc), through OpenCV's vectorised paths.
  CheckFrameFormat(frame);
  if (frame.format == PixelFormat::kYuyv) {
    cv::Mat y;
    cv::extractChannel(frame.image, y, 0);  // Y bytes, limited range
    y.convertTo(grey_, CV_8U, 255.0 / 219.0, -16.0 * 255.0 / 219.0);
  } else {
    cv::cvtColor(frame.image, grey_, cv::COLOR_BGR2GRAY);
  }
  cv::Mat soft8;
  ShrinkByBlocks(grey_, &soft8, kSoftScale);
  soft8.convertTo(soft_now_, CV_32F);
  if (background_.size() != grey_.size()) {
    grey_.convertTo(background_, CV_32F);
    soft_background_ = soft_now_.clone();
    previous_.release();
  }
  // Exposure and white balance drift move the whole frame: the median difference is that
  // global offset, not the ball.
  cv::Mat soft_diff = soft_now_ - soft_background_;
  std::vector<float> d(soft_diff.begin<float>(), soft_diff.end<float>());
  auto mid = d.begin() + static_cast<long>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  offset_ = d.empty() ? 0 : *mid;
  // Shadows of the hand and arm, and light changes, move soft and large regions: only what
  // stands out of its own neighbourhood (the high-passed difference) is ball-like.
  if (params_.highpass_sigma_px > 0) {
    soft_diff -= offset_;
    // A Gaussian leaves the inside of a disc of radius r only if it is several r wide: at 32 px
    // a ball of radius 115 px would keep only its rim.
    double sigma = params_.highpass_sigma_px;
    if (closeup_radius_px > 0) sigma = std::max(sigma, params_.closeup_highpass_radii * closeup_radius_px);
    cv::GaussianBlur(soft_diff, soft_change_, cv::Size(), sigma / kSoftScale);
  } else {
    soft_change_.release();
  }
}

void LumaContrast::ContrastPlanes(cv::Rect rect, int step, double blur_sigma_px,
                                  YccPlanes* out) const {
  rect &= cv::Rect(0, 0, grey_.cols, grey_.rows);
  out->rect = rect;
  out->step = step;
  // Decimated first (8-bit luma and the background each shrunk on their own), so that a
  // whole-frame search costs a quarter of the float work.
  cv::Mat diff, background;
  if (step > 1) {
    cv::Mat grey;
    ShrinkByBlocks(grey_(rect), &grey, step);
    grey.convertTo(diff, CV_32F);
    ShrinkByBlocks(background_(rect), &background, step);
  } else {
    grey_(rect).convertTo(diff, CV_32F);
    background = background_(rect);
  }
  diff -= background;
  diff -= offset_;
  if (!soft_change_.empty()) SubtractSoftChange(rect, step, &diff);
  if (params_.polarity < 0) diff = -diff;
  if (params_.polarity == 0) diff = cv::abs(diff);
  out->u = diff;
  if (blur_sigma_px > 0) cv::GaussianBlur(out->u, out->u, cv::Size(), blur_sigma_px);
  const float c = static_cast<float>(params_.clamp_luma);
  cv::min(out->u, c, out->u);
  cv::max(out->u, -c, out->u);
  out->y = cv::Mat(out->u.size(), CV_32F, cv::Scalar(kContrastLuma));
  out->v = cv::Mat::zeros(out->u.size(), CV_32F);
}

void LumaContrast::SubtractSoftChange(cv::Rect rect, int step, cv::Mat* diff) const {
  // The soft change, bilinear from the small copy (edges repeated), for this rect only. A
  // small pixel k covers frame pixels [8k, 8k + 8); an output pixel i covers [x0 + step i,
  // + step). Separable: each column's and each row's two source pixels and weights once
  // (cv::warpAffine took 86 of a 140 px window's 155 us).
  struct Tap {
    int a, b;
    float w;  // weight of b; a gets 1 - w
  };
  auto taps = [&](int n, int origin, int size) {
    std::vector<Tap> t(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      const double x = (origin + step * (i + 0.5)) / kSoftScale - 0.5;
      const double x0 = std::floor(x);
      const int a = static_cast<int>(x0);
      t[static_cast<size_t>(i)] = {std::clamp(a, 0, size - 1), std::clamp(a + 1, 0, size - 1),
                                   static_cast<float>(x - x0)};
    }
    return t;
  };
  const std::vector<Tap> cols = taps(diff->cols, rect.x, soft_change_.cols);
  const std::vector<Tap> rows = taps(diff->rows, rect.y, soft_change_.rows);
  if (rows.empty() || cols.empty()) return;
  // Each small row interpolated along x once (eight output rows share it at full
  // resolution), then each output row is a blend of two of them.
  const int first = rows.front().a, last = rows.back().b;
  const size_t w = cols.size();
  std::vector<float> across(static_cast<size_t>(last - first + 1) * w);
  for (int k = first; k <= last; ++k) {
    const float* s = soft_change_.ptr<float>(k);
    float* h = &across[static_cast<size_t>(k - first) * w];
    for (size_t i = 0; i < w; ++i) h[i] = s[cols[i].a] + cols[i].w * (s[cols[i].b] - s[cols[i].a]);
  }
  for (int j = 0; j < diff->rows; ++j) {
    const Tap& r = rows[static_cast<size_t>(j)];
    const float* top = &across[static_cast<size_t>(r.a - first) * w];
    const float* bottom = &across[static_cast<size_t>(r.b - first) * w];
    float* d = diff->ptr<float>(j);
    for (size_t i = 0; i < w; ++i) d[i] -= top[i] + r.w * (bottom[i] - top[i]);
  }
}

double LumaContrast::MovedFraction(cv::Rect2f box) const {
  if (previous_.size() != grey_.size()) return 0;
  const cv::Rect r = cv::Rect(box) & cv::Rect(0, 0, grey_.cols, grey_.rows);
  if (r.area() == 0) return 0;
  const int motion = static_cast<int>(std::lround(params_.motion_luma));
  int moved = 0;
  for (int j = r.y; j < r.y + r.height; ++j) {
    const uint8_t* pn = grey_.ptr<uint8_t>(j);
    const uint8_t* pp = previous_.ptr<uint8_t>(j);
    for (int i = r.x; i < r.x + r.width; ++i)
      if (std::abs(pn[i] - pp[i]) > motion) ++moved;
  }
  return static_cast<double>(moved) / r.area();
}

void LumaContrast::UpdateBackground(double cx, double cy, double r) {
  if (background_.empty()) return;
  const double keep = r > 0 ? params_.keep_out_radii * r + 4 : -1;
  const double rate = params_.background_rate;
  if (keep <= 0) {
    cv::accumulateWeighted(grey_, background_, rate);
    cv::accumulateWeighted(soft_now_, soft_background_, rate);
    return;
  }
  auto disc = [&](double scale, cv::Point* c, int* radius) {
    *c = cv::Point(static_cast<int>(std::lround((cx + 0.5) * scale - 0.5)),
                   static_cast<int>(std::lround((cy + 0.5) * scale - 0.5)));
    *radius = static_cast<int>(std::ceil(keep * scale));
  };
  cv::Point c;
  int radius = 0;
  // Full resolution: the keep-out disc's box saved, the whole frame blended, the disc put back
  // (the same numbers as a masked blend, at half its cost: 207 against 462 us on a 634x1750
  // frame).
  disc(1.0, &c, &radius);
  const cv::Rect box = cv::Rect(c.x - radius, c.y - radius, 2 * radius + 1, 2 * radius + 1) &
                       cv::Rect(0, 0, background_.cols, background_.rows);
  if (box.area() > 0) background_(box).copyTo(saved_);
  cv::accumulateWeighted(grey_, background_, rate);
  if (box.area() > 0) {
    keep_mask_.create(box.size(), CV_8U);
    keep_mask_.setTo(0);
    cv::circle(keep_mask_, c - box.tl(), radius, cv::Scalar(255), cv::FILLED);
    saved_.copyTo(background_(box), keep_mask_);
  }
  // The small copy, masked (a float image's masked blend rounds differently from its plain one).
  disc(1.0 / kSoftScale, &c, &radius);
  soft_keep_mask_.create(soft_background_.size(), CV_8U);
  soft_keep_mask_.setTo(255);
  cv::circle(soft_keep_mask_, c, radius, cv::Scalar(0), cv::FILLED);
  cv::accumulateWeighted(soft_now_, soft_background_, rate, soft_keep_mask_);
}

void LumaContrast::ForgetBall(double cx, double cy, double r) {
  if (background_.empty() || r <= 0) return;
  const double r_in = 1.5 * r + 2, r_out = 2.5 * r + 4;
  const cv::Rect box = cv::Rect(static_cast<int>(cx - r_out), static_cast<int>(cy - r_out),
                                static_cast<int>(2 * r_out + 2), static_cast<int>(2 * r_out + 2)) &
                       cv::Rect(0, 0, background_.cols, background_.rows);
  double sum = 0;
  int n = 0;
  for (int j = box.y; j < box.y + box.height; ++j)
    for (int i = box.x; i < box.x + box.width; ++i) {
      const double d = std::hypot(i - cx, j - cy);
      if (d >= r_in && d <= r_out) sum += background_.at<float>(j, i), ++n;
    }
  if (n == 0) return;
  const float mean = static_cast<float>(sum / n);
  for (int j = box.y; j < box.y + box.height; ++j)
    for (int i = box.x; i < box.x + box.width; ++i)
      if (std::hypot(i - cx, j - cy) < r_in) background_.at<float>(j, i) = mean;
  ShrinkByBlocks(background_, &soft_background_, kSoftScale);
}

}  // namespace bouncefit
