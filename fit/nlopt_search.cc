#include "fit/nlopt_search.h"

#include <nlopt.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

namespace bouncefit {

namespace {

struct Subproblem {
  FitObjective* f;
  std::vector<double> base;     // full normalised point; active coordinates overwritten
  std::vector<size_t> active;   // indices into the full point
  nlopt::opt* opt;
};

double SubObjective(const std::vector<double>& y, std::vector<double>& grad, void* data) {
  auto* s = static_cast<Subproblem*>(data);
  (void)grad;  // derivative-free
  if (s->f->stopped()) {
    s->opt->force_stop();
    return s->f->penalty();
  }
  std::vector<double> x = s->base;
  for (size_t i = 0; i < s->active.size(); ++i) x[s->active[i]] = y[i];
  return s->f->Evaluate(x).objective;
}

// One continuous round over `active` from x (updated to the optimum found).
void Continuous(FitObjective& f, const std::vector<size_t>& active, std::vector<double>* x,
                const NloptSearchOptions& o) {
  if (active.empty() || f.stopped()) return;
  const unsigned n = static_cast<unsigned>(active.size());
  nlopt::opt opt(n >= 2 ? nlopt::LN_BOBYQA : nlopt::LN_COBYLA, n);
  Subproblem sub{&f, *x, active, &opt};
  opt.set_lower_bounds(std::vector<double>(n, 0.0));
  opt.set_upper_bounds(std::vector<double>(n, 1.0));
  opt.set_initial_step(o.initial_step);
  opt.set_xtol_abs(o.xtol);
  opt.set_ftol_rel(o.ftol_rel);
  opt.set_maxeval(100000);  // the objective's own budget stops it
  opt.set_min_objective(SubObjective, &sub);
  std::vector<double> y(n);
  for (unsigned i = 0; i < n; ++i) y[i] = (*x)[active[i]];
  double value = 0;
  try {
    opt.optimize(y, value);
  } catch (const std::exception&) {
    // forced stop, round-off limited, ...: the objective kept the best point.
  }
  const auto best = f.best_x();
  if (!best.empty()) *x = best;
}

}  // namespace

SearchResult NloptSearch(const FitProblem& problem, const CoefficientValues& start,
                         const SearchOptions& options, const NloptSearchOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  FitObjective f(problem, options);
  const size_t n = problem.free.size();
  const double h = o.initial_step;

  // BOBYQA moves a start within one step of a bound onto the bound or one step inside it;
  // do the same so the screening points are its initial interpolation points.
  std::vector<double> x0 = f.ToUnit(start);
  f.Snap(&x0);
  for (size_t j = 0; j < n; ++j) {
    if (f.Level(j) > 0) continue;
    if (x0[j] <= 0) x0[j] = 0;
    else if (x0[j] <= h) x0[j] = h;
    else if (x0[j] >= 1) x0[j] = 1;
    else if (1 - x0[j] <= h) x0[j] = 1 - h;
  }

  // 1. Screening: x0 and two points along every coordinate, all at once.
  std::vector<std::vector<double>> design{x0};
  std::vector<std::pair<int, int>> pair(n, {-1, -1});
  std::vector<double> du(n, 0.0);
  for (size_t j = 0; j < n; ++j) {
    const auto& s = problem.free[j];
    const double range = s.upper - s.lower;
    if (!(range > 0)) continue;
    double a, b;
    if (f.Level(j) > 0) {
      const double level = f.Level(j);
      a = x0[j] + level <= 1 + 1e-12 ? level : -level;
      b = x0[j] - level >= -1e-12 ? -level : (a > 0 ? 2 * level : -2 * level);
    } else {
      const bool at_low = x0[j] <= 0, at_high = x0[j] >= 1;
      a = at_high ? -h : h;
      b = at_low ? 2 * h : (at_high ? -2 * h : -h);
    }
    auto xa = x0, xb = x0;
    xa[j] += a;
    xb[j] += b;
    pair[j] = {static_cast<int>(design.size()), static_cast<int>(design.size() + 1)};
    design.push_back(xa);
    design.push_back(xb);
    du[j] = a - b;
  }
  const auto screened = f.EvaluateBatch(design);

  // Jacobian (normalised units) and the coefficients with an effect.
  const size_t k = problem.recorded_m.size();
  std::vector<std::vector<double>> jac(k, std::vector<double>(n, 0.0));
  std::vector<double> effect(n, 0.0);
  for (size_t j = 0; j < n; ++j) {
    if (pair[j].first < 0) continue;
    const auto& ea = screened[pair[j].first];
    const auto& eb = screened[pair[j].second];
    if (!ea.ok || !eb.ok) {
      effect[j] = HUGE_VAL;  // a failure is an effect: keep it in the search
      for (size_t i = 0; i < k; ++i) jac[i][j] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    for (size_t i = 0; i < k; ++i) {
      jac[i][j] = (ea.simulated_m[i] - eb.simulated_m[i]) / du[j];
      effect[j] = std::max(effect[j], std::abs(ea.simulated_m[i] - eb.simulated_m[i]));
    }
  }
  std::vector<size_t> active;
  std::vector<std::string> inactive;
  for (size_t j = 0; j < n; ++j) {
    if (pair[j].first < 0) continue;
    if (effect[j] < o.min_effect_m) {
      inactive.push_back(problem.free[j].name);
      continue;
    }
    if (f.Level(j) == 0) active.push_back(j);
  }
  std::stable_sort(active.begin(), active.end(),
                   [&](size_t a, size_t b) { return effect[a] > effect[b]; });
  if (o.max_active > 0 && static_cast<int>(active.size()) > o.max_active)
    active.resize(o.max_active);
  std::sort(active.begin(), active.end());

  // 2. Continuous search from x0 (its initial points are cached already).
  std::vector<double> x = x0;
  // Discrete coordinates: adopt the best screened level before the continuous search.
  {
    int best_i = 0;
    for (size_t i = 1; i < screened.size(); ++i)
      if (screened[i].objective < screened[best_i].objective) best_i = static_cast<int>(i);
    for (size_t j = 0; j < n; ++j)
      if (f.Level(j) > 0) x[j] = design[best_i][j];
  }
  Continuous(f, active, &x, o);

  // 3. Neighbouring levels of the discrete coefficients, in parallel, at the optimum.
  if (o.search_discrete && !f.stopped()) {
    std::vector<std::vector<double>> trials;
    for (size_t j = 0; j < n; ++j) {
      const auto& s = problem.free[j];
      const double level = f.Level(j);
      if (!(level > 0)) continue;
      if (std::find(inactive.begin(), inactive.end(), s.name) != inactive.end()) continue;
      for (double d : {-level, level}) {
        auto xt = x;
        xt[j] += d;
        if (xt[j] >= -1e-12 && xt[j] <= 1 + 1e-12) trials.push_back(xt);
      }
    }
    const double before = f.best().objective;
    if (!trials.empty()) f.EvaluateBatch(trials);
    if (f.best().objective < before) {
      x = f.best_x();
      Continuous(f, active, &x, o);
    }
  }

  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SearchResult r = f.MakeResult(active.size() >= 2 ? "nlopt-bobyqa" : "nlopt-cobyla", wall);
  r.jacobian = jac;
  r.jacobian_at = f.ToValues(x0);
  r.inactive = inactive;
  return r;
}

}  // namespace bouncefit
