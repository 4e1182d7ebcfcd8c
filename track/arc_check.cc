#include "track/arc_check.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>

namespace bouncefit {

bool ArcCheck::Add(double t, double x, double y, double r, bool whole) {
  if (!samples_.empty() && t - samples_.back().t > params_.max_gap_s) samples_.clear();
  if (!samples_.empty() && t <= samples_.back().t) return ballistic_;
  if (!samples_.empty()) {
    const Sample& p = samples_.back();
    const double dt = t - p.t;
    if (std::hypot(x - p.x, y - p.y) > std::max(1.0, r) * dt / 0.1) moving_s_ += dt;
  }
  samples_.push_back({t, x, y, r, whole});
  if (samples_.size() > 64) samples_.erase(samples_.begin());
  if (!ballistic_ && StretchIsArc()) ballistic_ = true;
  return ballistic_;
}

double ArcCheck::RecentTravel(double span_s) const {
  if (samples_.empty()) return 0;
  double lo = samples_.back().y, hi = lo;
  for (auto it = samples_.rbegin(); it != samples_.rend() && samples_.back().t - it->t <= span_s; ++it)
    lo = std::min(lo, it->y), hi = std::max(hi, it->y);
  return hi - lo;
}

bool ArcCheck::PositionAt(double t, double* x, double* y) const {
  for (auto it = samples_.rbegin(); it != samples_.rend(); ++it)
    if (std::abs(it->t - t) < 1e-3) {
      *x = it->x, *y = it->y;
      return true;
    }
  return false;
}

bool ArcCheck::StretchIsArc() const {
  const int n = static_cast<int>(samples_.size());
  if (n < params_.min_samples) return false;
  // The shortest stretch ending now that is long enough in samples and in time.
  int first = n - params_.min_samples;
  while (first > 0 && samples_.back().t - samples_[first].t < params_.min_span_s) --first;
  if (samples_.back().t - samples_[first].t < 0.5 * params_.min_span_s) return false;
  const int m = n - first;
  double r = 0, lo = 1e30, hi = -1e30;
  cv::Mat A(m, 3, CV_64F), bx(m, 1, CV_64F), by(m, 1, CV_64F);
  const double t0 = samples_[first].t;
  for (int i = 0; i < m; ++i) {
    const Sample& s = samples_[first + i];
    if (!s.whole) return false;
    const double dt = s.t - t0;
    A.at<double>(i, 0) = 1, A.at<double>(i, 1) = dt, A.at<double>(i, 2) = dt * dt;
    bx.at<double>(i) = s.x, by.at<double>(i) = s.y;
    r += s.r / m;
    lo = std::min(lo, s.y), hi = std::max(hi, s.y);
  }
  if (hi - lo < params_.min_travel_radii * r) return false;
  cv::Mat cx, cy;
  if (!cv::solve(A, bx, cx, cv::DECOMP_SVD) || !cv::solve(A, by, cy, cv::DECOMP_SVD)) return false;
  const double ay = 2 * cy.at<double>(2), ax = 2 * cx.at<double>(2);
  if (ay < params_.min_accel_radii * r || std::abs(ax) > 0.35 * ay) return false;
  const cv::Mat ex = A * cx - bx, ey = A * cy - by;
  const double rms = std::sqrt((ex.dot(ex) + ey.dot(ey)) / m);
  return rms <= std::max(params_.max_rms_px, params_.max_rms_radii * r);
}

}  // namespace bouncefit
