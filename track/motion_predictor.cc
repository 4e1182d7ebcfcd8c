#include "track/motion_predictor.h"

#include <Eigen/Dense>

#include <cmath>

namespace bouncefit {

void MotionPredictor::Add(double t, double x, double y) {
  if (!hist_.empty() && t - hist_.back().t > params_.max_gap_s) hist_.clear();
  double px, py;
  if (hist_.size() >= 3 && Predict(t, &px, &py) &&
      std::hypot(px - x, py - y) > params_.new_arc_px) {
    // Keep only the newest sample: the arc it ends may have been a different one.
    const Sample last = hist_.back();
    hist_.clear();
    hist_.push_back(last);
    ++arcs_;
  }
  hist_.push_back({t, x, y});
  while (static_cast<int>(hist_.size()) > params_.history) hist_.pop_front();
}

bool MotionPredictor::Predict(double t, double* x, double* y, double* speed) const {
  if (hist_.empty()) return false;
  const auto& last = hist_.back();
  const size_t n = hist_.size();
  if (n == 1) {
    *x = last.x, *y = last.y;
    if (speed) *speed = 0;
    return true;
  }
  const int order = n >= 4 ? 2 : 1;
  // Least squares in tau = t - t_last.
  Eigen::MatrixXd a(n, order + 1);
  Eigen::VectorXd bx(n), by(n);
  for (size_t i = 0; i < n; ++i) {
    const double tau = hist_[i].t - last.t;
    for (int k = 0; k <= order; ++k) a(static_cast<long>(i), k) = std::pow(tau, k);
    bx[static_cast<long>(i)] = hist_[i].x;
    by[static_cast<long>(i)] = hist_[i].y;
  }
  const Eigen::MatrixXd ata = a.transpose() * a;
  const Eigen::VectorXd cx = ata.ldlt().solve(a.transpose() * bx);
  const Eigen::VectorXd cy = ata.ldlt().solve(a.transpose() * by);
  const double tau = t - last.t;
  double vx = cx[1], vy = cy[1];
  *x = cx[0] + cx[1] * tau;
  *y = cy[0] + cy[1] * tau;
  if (order == 2) {
    *x += cx[2] * tau * tau;
    *y += cy[2] * tau * tau;
    vx += 2 * cx[2] * tau;
    vy += 2 * cy[2] * tau;
  }
  if (speed) *speed = std::hypot(vx, vy);
  return std::isfinite(*x) && std::isfinite(*y);
}

}  // namespace bouncefit
