#include "track/color_lock.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "track/color_pick.h"

namespace bouncefit {

bool ColorLock::StartNamed(const Frame& frame, std::string* how) {
  const ColorModelParams& cp = config_.color;
  if (config_.luma_mode) {
    *how = (config_.color_name.empty() ? std::string("brightness") : config_.color_name) +
           StartBrightness(config_.luma.polarity);
  } else if (config_.has_color) {
    color_ = ColorModel::FromBgr(config_.color_bgr[0], config_.color_bgr[1],
                                 config_.color_bgr[2], cp);
    *how = "colour " + (config_.color_name.empty() ? std::string("given") : config_.color_name);
  } else if (config_.has_chroma) {
    color_ = ColorModel(config_.chroma_nu, config_.chroma_nv, cp);
    *how = config_.color_name.empty() ? std::string("colour given") : config_.color_name;
  } else if (config_.has_pick) {
    const PickedColor picked = PickColor(frame, config_.pick_x, config_.pick_y, cp, config_.blur_sigma_px);
    color_ = picked.color;
    *how = fmt::format("picked pixel {:.0f},{:.0f}", config_.pick_x, config_.pick_y);
    // Nearly grey: follow its brightness instead, brighter or darker than its surroundings.
    if (picked.grey)
      *how = fmt::format("picked pixel {:.0f},{:.0f}, nearly grey:{}", config_.pick_x, config_.pick_y,
                         StartBrightness(picked.polarity));
  } else {
    return false;
  }
  anchor_ = color_;
  if (!luma_) *how += ": " + color_.ToString();
  return true;
}

void ColorLock::StartColor(const ColorModel& color) {
  luma_.reset();
  color_ = color;
  anchor_ = color_;
}

std::string ColorLock::StartBrightness(int polarity, double contrast_luma) {
  LumaContrastParams params = config_.luma;
  params.polarity = polarity;
  // A ball that stands out of its surroundings by little (a white ball on a pale wall, a
  // camera's flat tone curve) stands out of the background model by about half as much: the
  // thresholds scale down with it, to a floor above the noise.
  const double scale = contrast_luma > 0 ? std::clamp(config_.luma_contrast_share * contrast_luma /
                                                          params.min_contrast_luma, config_.luma_min_scale, 1.0)
                                         : 1.0;
  params.min_contrast_luma *= scale;
  params.clamp_luma *= scale;
  luma_ = std::make_unique<LumaContrast>(params);
  color_ = LumaContrast::BallModel(params, config_.color);
  anchor_ = color_;
  return fmt::format(": brightness, {} than a background model by >= {:.0f} luma (clamped at {:.0f})",
                     polarity > 0 ? "brighter" : polarity < 0 ? "darker" : "brighter or darker", params.min_contrast_luma,
                     params.clamp_luma);
}

void ColorLock::Drop() {
  color_ = ColorModel();
  luma_.reset();
}

void ColorLock::Planes(const Frame& frame, cv::Rect rect, int step, double blur_sigma_px, YccPlanes* out) const {
  if (luma_)
    luma_->ContrastPlanes(rect, step, blur_sigma_px, out);
  else
    ExtractYcc(frame, rect, step, blur_sigma_px, out);
}

void ColorLock::Adapt(const YccPlanes& planes, double cx, double cy, double r) {
  // Slow by design: every 4th good frame, 4x the rate, the same time constant.
  if (luma_ || !(config_.adapt_rate > 0) || ++adapt_tick_ % 4 != 0) return;
  const float floor = static_cast<float>(config_.color.luma_floor);
  const float min_luma = static_cast<float>(config_.color.min_luma);
  double in_u = 0, in_v = 0, out_u = 0, out_v = 0;
  int in_n = 0, out_n = 0;
  const double r_in2 = 0.6 * 0.6 * r * r, r_lo2 = 1.4 * 1.4 * r * r, r_hi2 = 1.9 * 1.9 * r * r;
  for (int j = 0; j < planes.y.rows; ++j) {
    const double dy = planes.rect.y + j - cy;
    if (dy * dy > r_hi2) continue;
    const float* py = planes.y.ptr<float>(j);
    const float* pu = planes.u.ptr<float>(j);
    const float* pv = planes.v.ptr<float>(j);
    for (int i = 0; i < planes.y.cols; ++i) {
      const double dx = planes.rect.x + i - cx;
      const double d2 = dx * dx + dy * dy;
      if (py[i] < min_luma || (d2 > r_in2 && d2 < r_lo2) || d2 > r_hi2) continue;
      const float inv = 1.0f / std::max(py[i], floor);
      if (d2 <= r_in2) in_u += pu[i] * inv, in_v += pv[i] * inv, ++in_n;
      else out_u += pu[i] * inv, out_v += pv[i] * inv, ++out_n;
    }
  }
  if (in_n < 5) return;
  in_u /= in_n, in_v /= in_n;
  const double tol = color_.tolerance();
  if (std::hypot(in_u - color_.nu(), in_v - color_.nv()) > tol) return;
  if (out_n > 0) {
    out_u /= out_n, out_v /= out_n;
    // Surroundings that look like the ball: adapting now could drift onto them.
    if (std::hypot(out_u - color_.nu(), out_v - color_.nv()) < 1.5 * tol) return;
  }
  color_.AdaptTowards(in_u, in_v, std::min(1.0, 4 * config_.adapt_rate), anchor_,
                      config_.adapt_max_drift * std::hypot(anchor_.nu(), anchor_.nv()));
}

void ColorLock::UpdateBackground(bool found, const BallObservation& obs, double radius, double last_x,
                                 double last_y) {
  // The background is kept from absorbing the ball only while it moves or has just come to
  // rest: a lock on something static (a patch of wall that brightened) fades out.
  if (found && std::hypot(obs.cx - still_x_, obs.cy - still_y_) > 0.5 * radius + 1)
    still_x_ = obs.cx, still_y_ = obs.cy, still_frames_ = 0;
  else
    ++still_frames_;
  const bool keep = still_frames_ <= config_.luma_still_frames;
  luma_->UpdateBackground(last_x, last_y, keep ? radius : 0);
}

}  // namespace bouncefit
