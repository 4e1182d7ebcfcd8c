#include "track/color_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "track/ycc_planes.h"

namespace bouncefit {

ColorModel::ColorModel(double nu, double nv, ColorModelParams params)
    : valid_(true), nu_(nu), nv_(nv), params_(params) {
  const double mag = std::hypot(nu, nv);
  reach_end_ = mag < params.washed_out
                   ? std::max(mag, std::min(params.saturation_reach * mag, params.saturation_reach_max))
                   : mag;
  Update();
}

ColorModel ColorModel::FromBgr(double b, double g, double r, ColorModelParams params) {
  double y, u, v;
  BgrToYuv(b, g, r, &y, &u, &v);
  return FromYuv(y, u, v, params);
}

ColorModel ColorModel::FromYuv(double y, double u, double v, ColorModelParams params) {
  const double d = std::max(y, params.luma_floor);
  return ColorModel(u / d, v / d, params);
}

// Eight pixels a step where the processor has AVX2, four where not (the loop vectorizes either
// way): the same IEEE operations in every lane (no FMA), so the same distances bit for bit.
__attribute__((target_clones("avx2", "default")))
void ColorModel::DistanceRow(const float* y, const float* u, const float* v, int n, float* out,
                             uint8_t* match) const {
  const DistanceTerms terms = Terms();
  const float tol = ftol_;
  for (int i = 0; i < n; ++i) {
    const float d = terms.Of(y[i], u[i], v[i]);
    out[i] = d;
    match[i] = static_cast<uint8_t>(d <= tol ? 255 : 0);
  }
}

void ColorModel::Update() {
  const double mag = std::hypot(nu_, nv_);
  tol_ = std::max(params_.tolerance_rel * mag, params_.tolerance_min);
  if (keep_out_)
    tol_ = std::min(tol_, std::max(params_.tolerance_min,
                                   params_.keep_out_share * std::hypot(nu_ - keep_out_nu_, nv_ - keep_out_nv_)));
  du_ = mag > 1e-9 ? nu_ / mag : 0;
  dv_ = mag > 1e-9 ? nv_ / mag : 0;
  fnu_ = static_cast<float>(nu_);
  fnv_ = static_cast<float>(nv_);
  ftol_ = static_cast<float>(tol_);
  min_luma_ = static_cast<float>(params_.min_luma);
  luma_floor_ = static_cast<float>(std::max(1.0, params_.luma_floor));
  fdu_ = static_cast<float>(du_);
  fdv_ = static_cast<float>(dv_);
  freach_ = static_cast<float>(std::max(0.0, reach_end_ - mag));
}

void ColorModel::KeepOut(double nu, double nv) {
  keep_out_ = true, keep_out_nu_ = nu, keep_out_nv_ = nv;
  Update();
  const double mag = std::hypot(nu_, nv_);
  if (mag <= 1e-9 || reach_end_ <= mag) return;
  const double along = nu * du_ + nv * dv_;
  const double perp = std::abs(-nu * dv_ + nv * du_);
  if (perp > tol_ || along <= mag) return;  // off the hue ray, or no more saturated
  // The segment must end where that colour is still beyond the tolerance, with a margin.
  reach_end_ = std::clamp(along - std::sqrt(tol_ * tol_ - perp * perp) - 0.5 * tol_, mag, reach_end_);
  Update();
}

void ColorModel::AdaptTowards(double nu, double nv, double rate, const ColorModel& anchor,
                              double max_drift) {
  double a = nu_ + rate * (nu - nu_), b = nv_ + rate * (nv - nv_);
  const double du = a - anchor.nu_, dv = b - anchor.nv_;
  const double drift = std::hypot(du, dv);
  if (drift > max_drift && drift > 0) {
    a = anchor.nu_ + du * max_drift / drift;
    b = anchor.nv_ + dv * max_drift / drift;
  }
  nu_ = a;
  nv_ = b;
  Update();
}

cv::Scalar ColorModel::ApproxBgr() const {
  double b, g, r;
  YuvToBgr(128, nu_ * 128, nv_ * 128, &b, &g, &r);
  return cv::Scalar(b, g, r);
}

std::string ColorModel::ToString() const {
  const cv::Scalar c = ApproxBgr();
  return fmt::format("chroma/luma ({:.2f}, {:.2f}) +- {:.2f}, about BGR {:.0f},{:.0f},{:.0f}", nu_, nv_, tol_, c[0], c[1],
                     c[2]);
}

}  // namespace bouncefit
