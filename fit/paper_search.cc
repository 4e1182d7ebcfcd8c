#include "fit/paper_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace bouncefit {

namespace {

// Value of x with coordinate j set to u.
std::vector<double> With(std::vector<double> x, size_t j, double u) {
  x[j] = std::clamp(u, 0.0, 1.0);
  return x;
}

}  // namespace

SearchResult PaperSearch(const FitProblem& problem, const CoefficientValues& start,
                         const SearchOptions& options, const PaperSearchOptions& paper) {
  const auto t0 = std::chrono::steady_clock::now();
  // The paper's order; ties keep the model's order.
  FitProblem ordered = problem;
  std::stable_sort(ordered.free.begin(), ordered.free.end(),
                   [](const CoefficientSpec& a, const CoefficientSpec& b) {
                     return PaperPriority(a.name) < PaperPriority(b.name);
                   });
  SearchOptions serial = options;
  serial.threads = 1;
  FitObjective f(ordered, serial);

  std::vector<double> x = f.ToUnit(start);
  f.Snap(&x);
  double fx = f.Evaluate(x).objective;

  for (int sweep = 0; sweep < paper.max_sweeps && !f.stopped(); ++sweep) {
    const double sweep_start = fx;
    for (size_t j = 0; j < ordered.free.size() && !f.stopped(); ++j) {
      const auto& spec = ordered.free[j];
      const double range = spec.upper - spec.lower;
      if (!(range > 0)) continue;
      const double level = f.Level(j);  // one grid step (0: continuous)
      const double h = std::max(paper.initial_step, level);
      const double min_bracket = std::max(paper.min_bracket, level);

      // Direction from a finite difference.
      const double x0 = x[j];
      double best_u = x0, best_f = fx;
      double lo = std::max(0.0, x0 - h), hi = std::min(1.0, x0 + h);
      int dir = 0;
      if (hi > x0) {
        const double fp = f.Evaluate(With(x, j, hi)).objective;
        if (fp < best_f) dir = +1, best_u = hi, best_f = fp, lo = x0;
      }
      if (dir == 0 && lo < x0) {
        const double fm = f.Evaluate(With(x, j, lo)).objective;
        if (fm < best_f) dir = -1, best_u = lo, best_f = fm, hi = x0;
      }
      // Expand in the improving direction, doubling the step, until it gets worse or hits
      // the bound: [lo, hi] then brackets the best value.
      if (dir != 0) {
        double step = h;
        while (!f.stopped()) {
          const bool at_bound = dir > 0 ? best_u >= 1.0 : best_u <= 0.0;
          if (at_bound) {
            (dir > 0 ? hi : lo) = best_u;
            break;
          }
          step *= 2;
          const double c = std::clamp(best_u + dir * step, 0.0, 1.0);
          const double fc = f.Evaluate(With(x, j, c)).objective;
          if (fc < best_f) {
            (dir > 0 ? lo : hi) = best_u;
            best_u = c;
            best_f = fc;
          } else {
            (dir > 0 ? hi : lo) = c;
            break;
          }
        }
      }
      // Bisection-like refinement: halve the larger side of the bracket around the best.
      while (hi - lo > min_bracket && !f.stopped()) {
        const bool left = best_u - lo > hi - best_u;
        const double t = left ? (lo + best_u) / 2 : (best_u + hi) / 2;
        if (level > 0 && std::abs(t - best_u) < level * 0.5) break;
        std::vector<double> xt = With(x, j, t);
        f.Snap(&xt);
        const double ft = f.Evaluate(xt).objective;
        if (ft < best_f) {
          (t < best_u ? hi : lo) = best_u;
          best_u = xt[j];
          best_f = ft;
        } else {
          (t < best_u ? lo : hi) = t;
        }
      }
      x[j] = best_u;
      fx = best_f;
    }
    if (sweep_start - fx <= paper.min_sweep_gain * sweep_start) break;
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return f.MakeResult("paper", wall);
}

}  // namespace bouncefit
