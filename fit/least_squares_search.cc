#include "fit/least_squares_search.h"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace bouncefit {

namespace {

// Forward-difference Jacobian of the simulated heights at x (backward at the upper bound).
bool Jacobian(FitObjective& f, const std::vector<double>& x, const Evaluation& at, double step,
              Eigen::MatrixXd* J) {
  const size_t n = x.size();
  const std::vector<double> r0 = f.Residuals(at);
  const size_t k = r0.size();
  std::vector<std::vector<double>> pts;
  std::vector<double> du(n);
  for (size_t j = 0; j < n; ++j) {
    auto p = x;
    du[j] = x[j] + step <= 1 ? step : -step;
    p[j] += du[j];
    pts.push_back(p);
  }
  const auto e = f.EvaluateBatch(pts);
  J->resize(k, n);
  for (size_t j = 0; j < n; ++j) {
    if (!e[j].ok) return false;
    const std::vector<double> r = f.Residuals(e[j]);  // d(simulated) = -d(residual)
    for (size_t i = 0; i < k; ++i) (*J)(i, j) = (r0[i] - r[i]) / du[j];
  }
  return true;
}

}  // namespace

SearchResult LeastSquaresSearch(const FitProblem& problem, const CoefficientValues& start,
                                const SearchOptions& options, const LeastSquaresOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  FitObjective f(problem, options);
  const size_t n = problem.free.size(), k = problem.recorded_m.size();
  std::vector<double> x = f.ToUnit(start);
  Evaluation ex = f.Evaluate(x);
  double lambda = o.initial_lambda;
  Eigen::MatrixXd J;
  bool have_jacobian = false;
  for (int it = 0; it < o.max_iterations && ex.ok && !f.stopped(); ++it) {
    if (!Jacobian(f, x, ex, o.fd_step, &J)) break;
    have_jacobian = true;
    const std::vector<double> rv = f.Residuals(ex);
    Eigen::VectorXd res(static_cast<Eigen::Index>(rv.size()));
    for (size_t i = 0; i < rv.size(); ++i) res(static_cast<Eigen::Index>(i)) = rv[i];
    const Eigen::MatrixXd A = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * res;
    bool improved = false;
    while (lambda < 1e10 && !f.stopped()) {
      Eigen::MatrixXd M = A;
      for (size_t j = 0; j < n; ++j) M(j, j) += lambda * std::max(A(j, j), 1e-12) + 1e-15;
      const Eigen::VectorXd dx = M.ldlt().solve(g);
      std::vector<double> xn = x;
      for (size_t j = 0; j < n; ++j) xn[j] = std::clamp(x[j] + dx(j), 0.0, 1.0);
      if (xn == x) break;
      const Evaluation en = f.Evaluate(xn);
      if (en.ok && en.objective < ex.objective) {
        const double gain = (ex.objective - en.objective) / std::max(ex.objective, 1e-300);
        x = xn;
        ex = en;
        lambda = std::max(lambda / 4, 1e-9);
        improved = gain > o.min_relative_gain;
        break;
      }
      lambda *= 5;
    }
    if (!improved) break;
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SearchResult r = f.MakeResult("least-squares", wall);
  if (have_jacobian && ex.ok) {
    // Jacobian at the answer, for the uncertainties (cheap: one parallel batch).
    // Its own budget: the search may have stopped on its target or budget.
    SearchOptions jo = options;
    jo.target_rms_m = 0;
    jo.max_evaluations = static_cast<int>(n) + 1;
    FitObjective jf(problem, jo);
    Eigen::MatrixXd Jf;
    if (Jacobian(jf, x, ex, std::max(o.fd_step, 1e-4), &Jf)) {
      r.jacobian.assign(k, std::vector<double>(n, 0.0));  // heights rows only
      for (size_t i = 0; i < k; ++i)
        for (size_t j = 0; j < n; ++j) r.jacobian[i][j] = Jf(i, j);
      r.jacobian_at = f.ToValues(x);
      r.evaluations = f.evaluations() + jf.evaluations();
    }
  }
  return r;
}

}  // namespace bouncefit
