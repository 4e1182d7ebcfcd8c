#include "fit/restitution_points.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit {

namespace {

constexpr double kG = 9.81;

// Speed after falling from rest through h, and speed that rises through h, with drag c.
double FallSpeed(double h, double c) {
  return c * h < 1e-9 ? std::sqrt(2 * kG * h) : std::sqrt(kG / c * -std::expm1(-2 * c * h));
}
double RiseSpeed(double h, double c) {
  return c * h < 1e-9 ? std::sqrt(2 * kG * h) : std::sqrt(kG / c * std::expm1(2 * c * h));
}

// Upper quantile of chi-square with nu degrees of freedom at upper-tail probability p
// (Wilson-Hilferty; within a few percent for nu >= 1 at the tails used here).
double ChiSquareQuantile(double nu, double p) {
  // z for the upper tail, from a rational approximation of the normal quantile.
  const double t = std::sqrt(-2 * std::log(p));
  const double z = t - (2.515517 + 0.802853 * t + 0.010328 * t * t) /
                           (1 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
  const double a = 2 / (9 * nu);
  return nu * std::pow(1 - a + z * std::sqrt(a), 3);
}

// A small dense symmetric system: solved by Gauss-Jordan elimination with partial pivoting.
using Matrix = std::vector<std::vector<double>>;

// The inverse of a (n x n); false when it is singular.
bool Invert(Matrix a, Matrix* inverse) {
  const size_t n = a.size();
  Matrix inv(n, std::vector<double>(n, 0.0));
  for (size_t i = 0; i < n; ++i) inv[i][i] = 1;
  double scale = 0;
  for (const auto& row : a)
    for (double v : row) scale = std::max(scale, std::abs(v));
  for (size_t col = 0; col < n; ++col) {
    size_t pivot = col;
    for (size_t r = col + 1; r < n; ++r)
      if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
    if (!(std::abs(a[pivot][col]) > 1e-12 * scale)) return false;
    std::swap(a[col], a[pivot]);
    std::swap(inv[col], inv[pivot]);
    const double d = a[col][col];
    for (size_t j = 0; j < n; ++j) a[col][j] /= d, inv[col][j] /= d;
    for (size_t r = 0; r < n; ++r) {
      if (r == col || a[r][col] == 0) continue;
      const double f = a[r][col];
      for (size_t j = 0; j < n; ++j) a[r][j] -= f * a[col][j], inv[r][j] -= f * inv[col][j];
    }
  }
  *inverse = std::move(inv);
  return true;
}

struct LineFit {
  std::vector<double> beta;  // offsets a_0..a_{D-1} (or one common a), then k
  Matrix cov;
  double chi2 = 0;
  bool ok = false;
};

// e_i = a_{drop(i)} - k v_i (common: one a for every drop), weights 1/(sigma_i^2 + s^2).
LineFit Fit(const std::vector<RestitutionPoint>& pts, int drops, bool common, bool slope, double s) {
  const size_t na = common ? 1 : static_cast<size_t>(drops);
  const size_t n = na + (slope ? 1 : 0);
  Matrix A(n, std::vector<double>(n, 0.0));
  std::vector<double> b(n, 0.0);
  for (const auto& p : pts) {
    std::vector<double> x(n, 0.0);
    x[common ? 0 : static_cast<size_t>(p.drop)] = 1;
    if (slope) x[na] = -p.speed_mps;
    const double w = 1 / (p.sigma * p.sigma + s * s);
    for (size_t i = 0; i < n; ++i) {
      b[i] += w * p.e * x[i];
      for (size_t j = 0; j < n; ++j) A[i][j] += w * x[i] * x[j];
    }
  }
  LineFit f;
  if (!Invert(A, &f.cov)) return f;
  f.beta.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) f.beta[i] += f.cov[i][j] * b[j];
  for (const auto& p : pts) {
    const double model = f.beta[common ? 0 : static_cast<size_t>(p.drop)] - (slope ? f.beta[na] * p.speed_mps : 0);
    f.chi2 += (p.e - model) * (p.e - model) / (p.sigma * p.sigma + s * s);
  }
  f.ok = true;
  return f;
}

}  // namespace

std::vector<RestitutionPoint> MeasureRestitution(const std::vector<double>& apexes_m,
                                                 const std::vector<double>& sigmas_m,
                                                 double drag_per_m, int drop, int start_bounce,
                                                 double default_sigma_m) {
  std::vector<RestitutionPoint> out;
  // A height's sigma holds the scale's, common to every height of the drop, which a ratio
  // cancels: at most default_sigma_m here; what the bounces scatter beyond it,
  // CheckRestitution measures.
  auto sigma = [&](size_t i) {
    const double s = i < sigmas_m.size() ? sigmas_m[i] : 0;
    return s > 0 ? std::min(s, default_sigma_m) : default_sigma_m;
  };
  for (size_t i = 1; i < apexes_m.size(); ++i) {
    const double h0 = apexes_m[i - 1], h1 = apexes_m[i];
    if (!(h0 > 0) || !(h1 > 0)) continue;
    RestitutionPoint p;
    p.drop = drop;
    p.bounce = start_bounce + static_cast<int>(i);
    p.speed_mps = FallSpeed(h0, drag_per_m);
    p.e = RiseSpeed(h1, drag_per_m) / p.speed_mps;
    // e goes as sqrt(h1 / h0), drag aside.
    p.sigma = 0.5 * p.e * std::hypot(sigma(i) / h1, sigma(i - 1) / h0);
    out.push_back(p);
  }
  return out;
}

RestitutionConsistency CheckRestitution(const std::vector<RestitutionPoint>& points,
                                        const RestitutionConsistencyOptions& o) {
  RestitutionConsistency c;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.points = static_cast<int>(points.size());
  for (const auto& p : points) c.drops = std::max(c.drops, p.drop + 1);
  if (points.empty()) return c;
  std::vector<double> speeds;
  for (const auto& p : points) speeds.push_back(p.speed_mps);
  std::sort(speeds.begin(), speeds.end());
  c.reference_mps = o.reference_mps > 0 ? o.reference_mps : speeds[speeds.size() / 2];
  // The slope needs two speeds within a drop (a drop's offset takes one point alone).
  const bool slope = c.points > c.drops;
  const int dof = c.points - c.drops - (slope ? 1 : 0);
  // The scatter beyond the heights' uncertainty: what makes chi-square per degree of freedom 1
  // about each drop's own line (the drops' differences do not count as scatter).
  c.scatter = o.min_scatter;
  LineFit f = Fit(points, c.drops, false, slope, c.scatter);
  if (!f.ok) {
    c.e0 = c.k = c.sigma_e0 = c.sigma_k = nan;
    return c;
  }
  if (dof > 0 && f.chi2 > dof) {
    double lo = c.scatter, hi = 0.5;
    for (int it = 0; it < 50; ++it) {
      const double mid = 0.5 * (lo + hi);
      (Fit(points, c.drops, false, slope, mid).chi2 > dof ? lo : hi) = mid;
    }
    c.scatter = hi;
    f = Fit(points, c.drops, false, slope, c.scatter);
  }
  const size_t kd = static_cast<size_t>(c.drops);
  c.k = slope ? f.beta[kd] : 0;
  c.sigma_k = slope ? std::sqrt(f.cov[kd][kd]) : nan;
  for (int d = 0; d < c.drops; ++d) {
    const size_t i = static_cast<size_t>(d);
    c.drop_e.push_back(f.beta[i] - c.k * c.reference_mps);
    double var = f.cov[i][i];
    if (slope) var += c.reference_mps * c.reference_mps * f.cov[kd][kd] - 2 * c.reference_mps * f.cov[i][kd];
    c.drop_e_sigma.push_back(std::sqrt(std::max(var, 0.0)));
  }
  // One curve for every drop, or not: the offsets' chi-square against its quantile.
  const LineFit common = Fit(points, c.drops, true, slope, c.scatter);
  if (c.drops > 1 && common.ok) {
    c.chi2_drops = std::max(0.0, common.chi2 - f.chi2);
    c.drops_agree = c.chi2_drops <= ChiSquareQuantile(c.drops - 1, o.false_alarm);
  }
  // e0 and its sigma from the common line, widened by the drops' spread (Birge ratio).
  const LineFit& one = common.ok ? common : f;
  c.e0 = one.beta[0];
  c.sigma_e0 = std::sqrt(one.cov[0][0]);
  if (c.drops > 1 && common.ok) {
    const double birge = std::sqrt(c.chi2_drops / (c.drops - 1));
    c.sigma_e0 *= std::max(1.0, birge);
    if (slope) c.sigma_k = std::max(c.sigma_k, std::sqrt(common.cov[1][1]) * std::max(1.0, birge));
  }
  for (const auto& p : points) {
    const double model = f.beta[static_cast<size_t>(p.drop)] - c.k * p.speed_mps;
    const double sd = std::sqrt(p.sigma * p.sigma + c.scatter * c.scatter);
    std::string where = fmt::format("bounce {}", p.bounce);
    if (c.drops > 1) where = fmt::format("drop {} {}", p.drop + 1, where);
    if (p.e > 1 + 2 * p.sigma)
      c.suspect.push_back(fmt::format("{}: e {:.3f} at {:.2f} m/s, above 1 (higher than the apex before allows)",
                                      where, p.e, p.speed_mps));
    else if (dof > 0 && std::abs(p.e - model) > o.outlier_sigmas * sd)
      c.suspect.push_back(fmt::format("{}: e {:.3f} at {:.2f} m/s, {:+.3f} off its drop's line ({:.1f} sigma)", where,
                                      p.e, p.speed_mps, p.e - model, std::abs(p.e - model) / sd));
  }
  return c;
}

std::string DropsDisagreement(const RestitutionConsistency& r) {
  std::string each;
  for (size_t d = 0; d < r.drop_e.size(); ++d)
    each += fmt::format("{}drop {} {:.3f} +- {:.3f}", d ? ", " : "", d + 1, r.drop_e[d], r.drop_e_sigma[d]);
  return fmt::format("the drops disagree beyond their uncertainty: e at {:.1f} m/s is {} (the bounces of one ball on "
                     "one floor give one e: fit each drop on its own, or find which measured something else)",
                     r.reference_mps, each);
}

}  // namespace bouncefit
