#include "model/arc_apex.h"

#include <Eigen/Dense>

#include <cmath>

namespace bouncefit {

ArcApex FitArcApex(const std::vector<double>& t, const std::vector<double>& height) {
  ArcApex apex;
  const auto n = static_cast<Eigen::Index>(t.size());
  if (n < 3 || t.size() != height.size()) return apex;
  double t0 = 0;
  for (double v : t) t0 += v;
  t0 /= static_cast<double>(n);
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double dt = t[i] - t0;
    a(i, 0) = dt * dt;
    a(i, 1) = dt;
    a(i, 2) = 1;
    b(i) = height[i];
  }
  const Eigen::Vector3d c = a.colPivHouseholderQr().solve(b);
  if (!(c(0) < 0) || !std::isfinite(c(0))) return apex;
  const double dt_apex = -c(1) / (2 * c(0));
  apex.ok = true;
  apex.t = t0 + dt_apex;
  apex.height = c(2) - c(1) * c(1) / (4 * c(0));
  apex.curvature = 2 * c(0);
  apex.rms_residual = std::sqrt((a * c - b).squaredNorm() / static_cast<double>(n));
  return apex;
}

}  // namespace bouncefit
