#include "fit/update_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include <Eigen/Dense>

#include "fit/sensitivity.h"

namespace bouncefit {

double TimeStepOf(const CoefficientValues& values) {
  for (const auto& [name, v] : values)
    if (name.find("time_step") != std::string::npos) return v;
  return 0;
}

int IterationsOf(const CoefficientValues& values) {
  for (const auto& [name, v] : values)
    if (name.find("iterations") != std::string::npos) return static_cast<int>(std::lround(v));
  return 0;
}

FitUpdate ReportUpdate(const UpdateContext& c, const FitProblem& problem, const SearchResult& r, bool final,
                       const std::vector<std::vector<double>>& jacobian, int extra_evals, double wall_s,
                       const BallModel& model) {
  FitUpdate u;
  u.utime = c.utime;
  u.sequence = c.sequence;
  u.start_bounce = c.start_bounce;
  // This drop's last bounce fitted (a joint fit's recorded_m holds the other drops' too).
  u.after_bounce = c.after_bounce;
  u.final = final;
  u.cancelled = r.cancelled;
  u.model = model.name();
  u.method = r.method;
  u.values = r.values;
  u.drop_height_m = c.drop_height_m;
  u.recorded_m = problem.recorded_m;
  u.simulated_m = r.simulated_m;
  for (const auto& d : problem.other_drops) {
    u.other_drop_heights_m.push_back(d.drop_height_m);
    u.other_drop_bounces.push_back(d.bounces);
  }
  u.residual_m = RmsResidual(problem.recorded_m, r.simulated_m);
  if (problem.segments) {
    u.segment_simulated_m = r.simulated_m;
    u.segment_residual_m = u.residual_m;
  }
  u.evaluations = r.evaluations + extra_evals;
  u.wall_time_s = wall_s;
  u.time_step_s = TimeStepOf(r.values);
  u.iterations = IterationsOf(r.values);
  if (u.time_step_s == 0) u.time_step_s = c.time_step_s;
  if (u.iterations == 0) u.iterations = c.iterations;
  u.no_effect = r.inactive;
  if (std::isfinite(c.flight_clock_ratio))
    u.warning = fmt::format("the flight times between impacts are {:.2g}x what the heights give (the impacts "
                            "on another clock?): the heights are fitted, not the flights; the first fall is "
                            "read on the flights' clock",
                            c.flight_clock_ratio);

  std::vector<CoefficientEstimate> est;
  if (!jacobian.empty())
    est = EstimateUncertainty(problem.free, r.values, jacobian, u.residual_m, c.measurement_sigma_m);
  // The covariance of the identifiable ones, in their own units (what `predict` propagates:
  // e0 and its slope are strongly anti-correlated, their sigmas alone overstate the spread).
  if (!jacobian.empty()) {
    std::vector<size_t> cols;
    for (size_t j = 0; j < est.size() && j < problem.free.size(); ++j)
      if (est[j].identifiable) cols.push_back(j);
    const size_t k = jacobian.size(), n = cols.size();
    if (n > 0 && k >= n) {
      Eigen::MatrixXd J(k, n);
      for (size_t i = 0; i < k; ++i)
        for (size_t col = 0; col < n; ++col)
          J(i, col) = jacobian[i][cols[col]] / (problem.free[cols[col]].upper - problem.free[cols[col]].lower);
      double sigma = c.measurement_sigma_m;
      sigma = std::max(sigma, k > n ? u.residual_m * std::sqrt(double(k) / double(k - n)) : u.residual_m);
      const Eigen::MatrixXd JtJ = J.transpose() * J;
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(JtJ, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Eigen::VectorXd sv = svd.singularValues();
      Eigen::MatrixXd inv = Eigen::MatrixXd::Zero(n, n);
      for (Eigen::Index d = 0; d < sv.size(); ++d)
        if (sv(d) > 1e-12 * sv(0)) inv += svd.matrixV().col(d) * svd.matrixU().col(d).transpose() / sv(d);
      const Eigen::MatrixXd cov = sigma * sigma * inv;
      for (size_t col = 0; col < n; ++col) {
        u.covariance_names.push_back(problem.free[cols[col]].name);
        u.covariance.emplace_back();
        for (size_t d = 0; d < n; ++d)
          u.covariance.back().push_back(cov(static_cast<Eigen::Index>(col), static_cast<Eigen::Index>(d)));
      }
    }
  }
  for (const auto& s : c.reported) {
    CoefficientEstimate e;
    auto it = std::find_if(est.begin(), est.end(), [&](const auto& x) { return x.name == s.name; });
    if (it != est.end()) {
      e = *it;
    } else {
      e.name = s.name;
      e.unit = s.unit;
      auto v = r.values.find(s.name);
      e.value = v != r.values.end() ? v->second : s.default_value;
      e.sigma = std::numeric_limits<double>::quiet_NaN();
      e.note = jacobian.empty() ? "no sensitivity computed" : "held fixed in this update";
      bool searched = false;
      for (const auto& f : problem.free) searched = searched || f.name == s.name;
      if (searched) e.note = "no sensitivity computed";
    }
    if (std::count(r.inactive.begin(), r.inactive.end(), s.name)) e.note = "no effect on the heights";
    if (!e.identifiable) u.unidentified.push_back(e.name);
    if (e.note == "no effect on the heights" && !std::count(u.no_effect.begin(), u.no_effect.end(), e.name))
      u.no_effect.push_back(e.name);
    u.coefficients.push_back(e);
  }
  return u;
}

}  // namespace bouncefit
