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

// BOBYQA's initial step for a normalised coordinate u: `h`, shortened to stay inside the
// bounds (so BOBYQA keeps the start where it is); a start within h/10 of a bound is put on
// it. Updates *u; returns the step.
double StartStep(double* u, double h) {
  *u = std::clamp(*u, 0.0, 1.0);
  const double d = std::min(*u, 1 - *u);
  if (d < h / 10) {
    *u = *u < 0.5 ? 0.0 : 1.0;
    return h;
  }
  return std::min(h, 0.9 * d);
}

// One continuous round over `active` from x (updated to the optimum found).
void Continuous(FitObjective& f, const std::vector<size_t>& active, std::vector<double>* x,
                const NloptSearchOptions& o) {
  if (active.empty() || f.stopped()) return;
  const unsigned n = static_cast<unsigned>(active.size());
  // Initial steps that keep BOBYQA from moving the start (it moves a start within one step
  // of a bound onto it or one step inside, which would throw a good warm start away), then
  // its 2n+1 initial interpolation points evaluated at once, in parallel: the serial
  // optimiser finds them cached.
  std::vector<double> dx(n);
  for (unsigned i = 0; i < n; ++i) dx[i] = StartStep(&(*x)[active[i]], o.initial_step);
  if (n >= 2) {
    std::vector<std::vector<double>> design{*x};
    for (unsigned i = 0; i < n; ++i) {
      const size_t j = active[i];
      const double sj = dx[i];
      const bool at_low = (*x)[j] <= 0, at_high = (*x)[j] >= 1;
      auto xa = *x, xb = *x;
      xa[j] += at_high ? -sj : sj;
      xb[j] += at_low ? 2 * sj : (at_high ? -2 * sj : -sj);
      design.push_back(xa);
      design.push_back(xb);
    }
    f.EvaluateBatch(design);
  }
  nlopt::opt opt(n >= 2 ? nlopt::LN_BOBYQA : nlopt::LN_COBYLA, n);
  Subproblem sub{&f, *x, active, &opt};
  opt.set_lower_bounds(std::vector<double>(n, 0.0));
  opt.set_upper_bounds(std::vector<double>(n, 1.0));
  opt.set_initial_step(dx);
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

  // The steps BOBYQA will start with, so the screening points are its initial points.
  std::vector<double> x0 = f.ToUnit(start);
  f.Snap(&x0);
  std::vector<double> start_step(n, h);
  for (size_t j = 0; j < n; ++j)
    start_step[j] = f.Level(j) > 0 ? f.Level(j) : StartStep(&x0[j], h);

  // 1. Screening, all at once: x0 and one step along every coordinate (the first half of
  //    BOBYQA's initial design; the other half is evaluated only for the coefficients that
  //    turn out to matter).
  std::vector<std::vector<double>> design{x0};
  std::vector<int> index(n, -1);
  std::vector<double> du(n, 0.0);
  for (size_t j = 0; j < n; ++j) {
    const auto& s = problem.free[j];
    if (!(s.upper - s.lower > 0)) continue;
    const double step = start_step[j];
    const double a = x0[j] + step <= 1 + 1e-12 ? step : -step;
    auto xa = x0;
    xa[j] += a;
    index[j] = static_cast<int>(design.size());
    design.push_back(xa);
    du[j] = a;
  }
  const auto screened = f.EvaluateBatch(design);

  // Jacobian (normalised units) and the coefficients with an effect.
  const size_t k = problem.recorded_m.size();
  std::vector<std::vector<double>> jac(k, std::vector<double>(n, 0.0));
  std::vector<double> effect(n, 0.0);
  const auto& e0 = screened[0];
  for (size_t j = 0; j < n; ++j) {
    if (index[j] < 0) continue;
    const auto& ea = screened[index[j]];
    if (!ea.ok || !e0.ok) {
      effect[j] = HUGE_VAL;  // a failure is an effect: keep it in the search
      for (size_t i = 0; i < k; ++i) jac[i][j] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    for (size_t i = 0; i < k; ++i) {
      jac[i][j] = (ea.simulated_m[i] - e0.simulated_m[i]) / du[j];
      effect[j] = std::max(effect[j], std::abs(ea.simulated_m[i] - e0.simulated_m[i]));
    }
  }
  std::vector<size_t> active;
  std::vector<std::string> inactive;
  for (size_t j = 0; j < n; ++j) {
    if (index[j] < 0) continue;
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

  // 2. Continuous search from x0 (half its initial points are cached already).
  std::vector<double> x = x0;
  Continuous(f, active, &x, o);
  // BOBYQA shrinks its trust region as it converges; on a noisy objective (heights measured
  // on camera-rate samples) it can stall early. Restart from the best point while that pays.
  // A restart that gains nothing gets one more try with a wider initial step (out of a
  // local dip of the noise); two in a row end the search.
  NloptSearchOptions wide = o;
  wide.initial_step = std::min(0.25, 3 * o.initial_step);
  bool widened = false;
  for (int restart = 0; restart < o.max_restarts && !f.stopped(); ++restart) {
    const double before = f.best().objective;
    Continuous(f, active, &x, widened ? wide : o);
    const bool gained = f.best().objective < before * (1 - o.restart_min_gain);
    if (!gained && widened) break;
    widened = !gained;
  }

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

  // 4. Local sampling with what is left of the budget.
  if (o.sample_after && !f.stopped()) {
    x = f.best_x();
    LocalSampling(f, active, &x, o.sampling);
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
