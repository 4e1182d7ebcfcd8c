#include "fit/sensitivity.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit {

std::vector<CoefficientEstimate> EstimateUncertainty(
    const std::vector<CoefficientSpec>& free, const CoefficientValues& values,
    const std::vector<std::vector<double>>& jacobian_unit, double residual_rms_m,
    double measurement_sigma_m, const SensitivityOptions& o) {
  const int n = static_cast<int>(free.size());
  const int k = static_cast<int>(jacobian_unit.size());
  std::vector<CoefficientEstimate> out(n);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int j = 0; j < n; ++j) {
    out[j].name = free[j].name;
    out[j].unit = free[j].unit;
    auto it = values.find(free[j].name);
    out[j].value = it != values.end() ? it->second : free[j].default_value;
    out[j].sigma = nan;
    for (int i = 0; i < k; ++i)
      if (j < static_cast<int>(jacobian_unit[i].size())) {
        const double d = std::abs(jacobian_unit[i][j]);
        out[j].height_effect_m = std::isnan(d) ? nan : std::max(out[j].height_effect_m, d);
        if (std::isnan(d)) break;
      }
  }
  if (k == 0) {
    for (auto& e : out) e.note = "no bounces";
    return out;
  }
  // Columns with an effect take part; scaled to unit norm for a well-conditioned SVD.
  std::vector<int> cols;
  for (int j = 0; j < n; ++j) {
    if (std::isnan(out[j].height_effect_m)) {
      out[j].note = "sensitivity unknown (a simulation next to the fit failed)";
      continue;
    }
    if (!(out[j].height_effect_m >= o.min_effect_m) || !(free[j].upper > free[j].lower)) {
      out[j].note = "no effect on the heights";
      continue;
    }
    cols.push_back(j);
  }
  if (cols.empty()) return out;
  const int p = static_cast<int>(cols.size());
  Eigen::MatrixXd J(k, p);
  Eigen::VectorXd scale(p);
  for (int c = 0; c < p; ++c) {
    for (int i = 0; i < k; ++i) J(i, c) = jacobian_unit[i][cols[c]];
    scale(c) = J.col(c).norm();
    J.col(c) /= scale(c);
  }
  // Scatter: the residual's, with the degrees of freedom left, but never below the
  // measurement uncertainty.
  double sigma = measurement_sigma_m;
  if (k > p) sigma = std::max(sigma, residual_rms_m * std::sqrt(double(k) / double(k - p)));
  else sigma = std::max(sigma, residual_rms_m);
  if (!(sigma > 0)) sigma = 1e-4;

  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  const Eigen::MatrixXd V = svd.matrixV();
  const double smax = sv.size() > 0 ? sv(0) : 0.0;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(p, p);
  std::vector<double> null_load(p, 0.0);
  for (int d = 0; d < p; ++d) {
    const double s = d < sv.size() ? sv(d) : 0.0;
    if (s > o.null_tolerance * smax && s > 0) {
      cov += V.col(d) * V.col(d).transpose() / (s * s);
    } else {
      for (int c = 0; c < p; ++c) null_load[c] = std::max(null_load[c], std::abs(V(c, d)));
    }
  }
  for (int c = 0; c < p; ++c) {
    auto& e = out[cols[c]];
    const double range = free[cols[c]].upper - free[cols[c]].lower;
    if (null_load[c] > o.null_loading) {
      e.note = "not determined by these bounces (degenerate with other coefficients)";
      continue;
    }
    // Back to the coefficient's own unit: unit column scale, then the range.
    const double sd_unit = sigma * std::sqrt(std::max(cov(c, c), 0.0)) / scale(c);
    const double sd = sd_unit * range;
    if (!(sd <= o.max_sigma_fraction * range)) {
      e.note = "weakly determined (uncertainty spans the bounds)";
      continue;
    }
    e.sigma = sd;
    e.identifiable = true;
  }
  return out;
}

std::vector<std::vector<double>> HeightsJacobian(FitObjective& f, const CoefficientValues& values,
                                                 double step) {
  const auto& free = f.problem().free;
  const size_t n = free.size(), k = f.problem().recorded_m.size();
  std::vector<double> x = f.ToUnit(values);
  std::vector<std::vector<double>> pts;
  std::vector<double> du(n, 0);
  for (size_t j = 0; j < n; ++j) {
    const double h = std::max(step, f.Level(j));
    auto a = x, b = x;
    a[j] = std::min(1.0, x[j] + h);
    b[j] = std::max(0.0, x[j] - h);
    du[j] = a[j] - b[j];
    pts.push_back(a);
    pts.push_back(b);
  }
  const auto e = f.EvaluateBatch(pts);
  std::vector<std::vector<double>> jac(k, std::vector<double>(n, 0.0));
  for (size_t j = 0; j < n; ++j) {
    const auto& ea = e[2 * j];
    const auto& eb = e[2 * j + 1];
    if (!ea.ok || !eb.ok || !(du[j] > 0)) {
      // A failed neighbour says nothing about the slope: unknown, not zero.
      for (size_t i = 0; i < k; ++i) jac[i][j] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    for (size_t i = 0; i < k; ++i) jac[i][j] = (ea.simulated_m[i] - eb.simulated_m[i]) / du[j];
  }
  return jac;
}

}  // namespace bouncefit
