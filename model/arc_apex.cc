#include "model/arc_apex.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace bouncefit {

// Standard C++ only (`fit --export` ships this file with the soft ball's world): the
// parabola h = c0 tau^2 + c1 tau + c2 in the scaled time tau = (t - mean) / half-span, which
// keeps the 3x3 normal equations well conditioned (tau in [-1, 1]); solved by Gaussian
// elimination with partial pivoting.
ArcApex FitArcApex(const std::vector<double>& t, const std::vector<double>& height) {
  ArcApex apex;
  const size_t n = t.size();
  if (n < 3 || n != height.size()) return apex;
  double t0 = 0;
  for (double v : t) t0 += v;
  t0 /= static_cast<double>(n);
  double span = 0;
  for (double v : t) span = std::max(span, std::abs(v - t0));
  if (!(span > 0) || !std::isfinite(span)) return apex;

  // Normal equations m c = rhs, basis (tau^2, tau, 1).
  double m[3][3] = {}, rhs[3] = {};
  for (size_t i = 0; i < n; ++i) {
    const double tau = (t[i] - t0) / span;
    const double b[3] = {tau * tau, tau, 1};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[r][c] += b[r] * b[c];
      rhs[r] += b[r] * height[i];
    }
  }
  for (int col = 0; col < 3; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 3; ++r)
      if (std::abs(m[r][col]) > std::abs(m[pivot][col])) pivot = r;
    if (!(std::abs(m[pivot][col]) > 1e-12 * static_cast<double>(n))) return apex;  // rank < 3
    if (pivot != col) {
      for (int c = 0; c < 3; ++c) std::swap(m[col][c], m[pivot][c]);
      std::swap(rhs[col], rhs[pivot]);
    }
    for (int r = col + 1; r < 3; ++r) {
      const double f = m[r][col] / m[col][col];
      for (int c = col; c < 3; ++c) m[r][c] -= f * m[col][c];
      rhs[r] -= f * rhs[col];
    }
  }
  double c[3];
  for (int r = 2; r >= 0; --r) {
    double v = rhs[r];
    for (int k = r + 1; k < 3; ++k) v -= m[r][k] * c[k];
    c[r] = v / m[r][r];
  }
  if (!(c[0] < 0) || !std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]))
    return apex;
  const double tau_apex = -c[1] / (2 * c[0]);
  apex.ok = true;
  apex.t = t0 + tau_apex * span;
  apex.height = c[2] - c[1] * c[1] / (4 * c[0]);
  apex.curvature = 2 * c[0] / (span * span);
  double ss = 0;
  for (size_t i = 0; i < n; ++i) {
    const double tau = (t[i] - t0) / span;
    const double e = c[0] * tau * tau + c[1] * tau + c[2] - height[i];
    ss += e * e;
  }
  apex.rms_residual = std::sqrt(ss / static_cast<double>(n));
  return apex;
}

}  // namespace bouncefit
