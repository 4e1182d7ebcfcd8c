#include "track/luma_contrast.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

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

void LumaContrast::SetFrame(const Frame& frame) {
  if (!now_.y.empty()) std::swap(previous_, now_.y);
  // Luma only (the same BT.601 weights as ExtractYcc), through OpenCV's vectorised paths.
  CheckFrameFormat(frame);
  cv::Mat grey;
  if (frame.format == PixelFormat::kYuyv) {
    cv::extractChannel(frame.image, grey, 0);  // Y bytes, limited range
    grey.convertTo(now_.y, CV_32F, 255.0 / 219.0, -16.0 * 255.0 / 219.0);
  } else {
    cv::cvtColor(frame.image, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(now_.y, CV_32F);
  }
  now_.rect = cv::Rect(0, 0, now_.y.cols, now_.y.rows);
  now_.step = 1;
  if (background_.size() != now_.y.size()) background_ = now_.y.clone();
  // Exposure and white balance drift move the whole frame: the median difference over a
  // coarse grid is that global offset, not the ball.
  std::vector<float> d;
  for (int j = 0; j < now_.y.rows; j += 8)
    for (int i = 0; i < now_.y.cols; i += 8)
      d.push_back(now_.y.at<float>(j, i) - background_.at<float>(j, i));
  auto mid = d.begin() + static_cast<long>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  cv::subtract(now_.y, background_, diff_);
  diff_ -= *mid;
  // Shadows of the hand and arm, and light changes, move soft and large regions: only what
  // stands out of its own neighbourhood (the high-passed difference) is ball-like.
  if (params_.highpass_sigma_px > 0) {
    cv::Mat low;
    cv::resize(diff_, low, cv::Size(std::max(1, diff_.cols / 8), std::max(1, diff_.rows / 8)), 0,
               0, cv::INTER_AREA);
    cv::GaussianBlur(low, low, cv::Size(), params_.highpass_sigma_px / 8);
    cv::resize(low, low, diff_.size(), 0, 0, cv::INTER_LINEAR);
    diff_ -= low;
  }
}

void LumaContrast::ContrastPlanes(cv::Rect rect, int step, double blur_sigma_px,
                                  YccPlanes* out) const {
  rect &= cv::Rect(0, 0, now_.y.cols, now_.y.rows);
  out->rect = rect;
  out->step = step;
  cv::Mat diff = diff_(rect).clone();
  if (params_.polarity < 0) diff = -diff;
  if (params_.polarity == 0) diff = cv::abs(diff);
  if (step > 1)
    cv::resize(diff, out->u, cv::Size(rect.width / step, rect.height / step), 0, 0, cv::INTER_AREA);
  else
    out->u = diff;
  if (blur_sigma_px > 0) cv::GaussianBlur(out->u, out->u, cv::Size(), blur_sigma_px);
  const float c = static_cast<float>(params_.clamp_luma);
  cv::min(out->u, c, out->u);
  cv::max(out->u, -c, out->u);
  out->y = cv::Mat(out->u.size(), CV_32F, cv::Scalar(kContrastLuma));
  out->v = cv::Mat::zeros(out->u.size(), CV_32F);
}

double LumaContrast::MovedFraction(cv::Rect2f box) const {
  if (previous_.size() != now_.y.size()) return 0;
  const cv::Rect r = cv::Rect(box) & cv::Rect(0, 0, now_.y.cols, now_.y.rows);
  if (r.area() == 0) return 0;
  int moved = 0;
  for (int j = r.y; j < r.y + r.height; ++j) {
    const float* pn = now_.y.ptr<float>(j);
    const float* pp = previous_.ptr<float>(j);
    for (int i = r.x; i < r.x + r.width; ++i)
      if (std::abs(pn[i] - pp[i]) > params_.motion_luma) ++moved;
  }
  return static_cast<double>(moved) / r.area();
}

void LumaContrast::UpdateBackground(double cx, double cy, double r) {
  if (background_.empty()) return;
  const double keep = r > 0 ? params_.keep_out_radii * r + 4 : -1;
  if (keep > 0) {
    keep_mask_.create(background_.size(), CV_8U);
    keep_mask_.setTo(255);
    cv::circle(keep_mask_, cv::Point(static_cast<int>(std::lround(cx)), static_cast<int>(std::lround(cy))),
               static_cast<int>(std::ceil(keep)), cv::Scalar(0), cv::FILLED);
    cv::accumulateWeighted(now_.y, background_, params_.background_rate, keep_mask_);
  } else {
    cv::accumulateWeighted(now_.y, background_, params_.background_rate);
  }
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
}

}  // namespace bouncefit
