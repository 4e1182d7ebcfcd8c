#include "fit/live_step.h"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace bouncefit {

SearchResult LiveStep(const FitProblem& problem, const CoefficientValues& start,
                      const SearchOptions& options, const LiveStepOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  FitObjective f(problem, options);
  const size_t n = problem.free.size(), k = problem.recorded_m.size();
  std::vector<double> x = f.ToUnit(start);
  std::vector<std::vector<double>> jac_out;
  for (int round = 0; round < o.rounds && !f.stopped(); ++round) {
    // Round 1: x and x + h e_j together.
    std::vector<std::vector<double>> pts{x};
    std::vector<double> du(n);
    for (size_t j = 0; j < n; ++j) {
      auto p = x;
      const double h = std::max(o.fd_step, f.Level(j));
      du[j] = x[j] + h <= 1 ? h : -h;
      p[j] += du[j];
      pts.push_back(p);
    }
    const auto e = f.EvaluateBatch(pts);
    if (!e[0].ok) break;
    Eigen::MatrixXd J(k, n);
    Eigen::VectorXd res(k);
    for (size_t i = 0; i < k; ++i) res(i) = problem.recorded_m[i] - e[0].simulated_m[i];
    bool usable = true;
    for (size_t j = 0; j < n; ++j) {
      if (!e[j + 1].ok) usable = false;
      for (size_t i = 0; i < k; ++i)
        J(i, j) = e[j + 1].ok ? (e[j + 1].simulated_m[i] - e[0].simulated_m[i]) / du[j] : 0.0;
    }
    if (round == 0) {
      jac_out.assign(k, std::vector<double>(n, 0.0));
      for (size_t i = 0; i < k; ++i)
        for (size_t j = 0; j < n; ++j) jac_out[i][j] = J(i, j);
    }
    if (!usable) break;
    // Damped Gauss-Newton step, clipped per coefficient and to the box.
    Eigen::MatrixXd A = J.transpose() * J;
    for (size_t j = 0; j < n; ++j) A(j, j) += o.damping * std::max(A(j, j), 1e-12) + 1e-12;
    const Eigen::VectorXd d = A.ldlt().solve(J.transpose() * res);
    // Round 2: the step and fractions of it, at once (as many as there are threads, >= 2).
    std::vector<std::vector<double>> line;
    const int tries = std::max(2, f.threads());
    for (int t = 0; t < tries; ++t) {
      const double scale = std::pow(0.5, t);
      auto p = x;
      for (size_t j = 0; j < n; ++j)
        p[j] = std::clamp(x[j] + std::clamp(scale * d(j), -o.max_step, o.max_step), 0.0, 1.0);
      line.push_back(p);
    }
    f.EvaluateBatch(line);
    const auto best = f.best_x();
    if (best == x) break;
    x = best;
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SearchResult r = f.MakeResult("live-gauss-newton", wall);
  r.jacobian = jac_out;
  r.jacobian_at = f.ToValues(f.ToUnit(start));
  return r;
}

}  // namespace bouncefit
