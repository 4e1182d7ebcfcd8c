#include "fit/restitution_fit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "fit/least_squares_search.h"
#include "fit/sensitivity.h"

namespace bouncefit {

namespace {

CoefficientSpec Narrowed(const BallModel& model, const std::string& name, double lower,
                         double upper) {
  for (auto s : model.Coefficients())
    if (s.name == name) {
      s.lower = std::max(s.lower, lower);
      s.upper = std::min(s.upper, upper);
      return s;
    }
  throw std::invalid_argument("model '" + model.name() + "' has no coefficient '" + name + "'");
}

}  // namespace

TimedDrag DragFromFall(const FitProblem& p, const BallModel& point_mass, const CoefficientValues& at,
                       const CoefficientSpec& drag) {
  const double t = p.start_fall_s, sigma_t = p.start_fall_sigma_s, h = p.simulation.drop_height_m;
  if (!(t > 0) || !(sigma_t > 0) || !(h > 0)) return {};
  auto fall = [&](double cd) {
    CoefficientValues v = at;
    v[drag.name] = cd;
    SimulationOptions o;
    o.drop_height_m = h;
    o.duration_s = 3 * std::sqrt(2 * h / 9.81) + 0.5;  // a fall to the floor, and its rebound
    o.max_bounces = 1;
    const SimulationResult r = SimulateSafely(point_mass, v, o);
    return r.ok && !r.impact_times_s.empty() ? r.impact_times_s.front() : std::nan("");
  };
  const double fastest = fall(drag.lower), slowest = fall(drag.upper);
  if (!(std::isfinite(fastest) && std::isfinite(slowest) && slowest > fastest)) return {};
  if (t < fastest - 2 * sigma_t || t > slowest + 2 * sigma_t) return {};
  // The fall lengthens with the drag: bisection inside the range.
  double lo = drag.lower, hi = drag.upper;
  if (t <= fastest) hi = lo;
  else if (t >= slowest) lo = hi;
  for (int i = 0; i < 50 && hi - lo > 1e-6 * (drag.upper - drag.lower); ++i) {
    const double mid = 0.5 * (lo + hi);
    (fall(mid) < t ? lo : hi) = mid;
  }
  TimedDrag out;
  out.value = 0.5 * (lo + hi);
  const double step = 0.02 * (drag.upper - drag.lower);
  const double a = std::max(drag.lower, out.value - step), b = std::min(drag.upper, out.value + step);
  const double slope = (fall(b) - fall(a)) / (b - a);
  out.sigma = slope > 0 ? sigma_t / slope : std::nan("");
  return out;
}

std::string SoftLawName(const std::string& n) {
  if (n == "restitution") return "rebound_restitution";
  if (n == "restitution_per_mps") return "rebound_restitution_per_mps";
  if (n == "drag_coefficient") return "drag";
  return n;
}

CoefficientValues WithRestitutionLaw(CoefficientValues values, double restitution,
                                     double restitution_per_mps, double drag) {
  values["rebound_restitution"] = restitution;
  values["rebound_restitution_per_mps"] = restitution_per_mps;
  values["drag"] = drag;
  // Bullet's air resistance (damping) is Cd's; its internal gas (pressure, volume
  // conservation) pushes an unevenly squashed ball as a whole (docs/MODEL.md), measured as
  // a rebound 6% short of the law's after a 1 m ping-pong impact: off.
  values["damping"] = 0;
  values["pressure"] = 0;
  values["volume_conservation"] = 0;
  return values;
}

RestitutionFit FitRestitutionCurve(const FitProblem& soft, const BallModel& point_mass,
                                   const SearchOptions& options, const RestitutionFitOptions& o) {
  RestitutionFit out;
  // Stage 1: the point mass on the same heights, from its defaults (the ball's preset).
  // Coefficients the heights cannot fit hold the preset's value (RestitutionFitOptions).
  FitProblem pm = soft;
  pm.model = &point_mass;
  pm.fixed.clear();
  pm.segments = false;  // not chaotic: its free drop is the best estimate
  pm.grid.clear();
  pm.safety = nullptr;  // a point mass cannot diverge
  pm.safety_simulations = 0;
  const std::vector<CoefficientSpec> all = point_mass.Coefficients();
  CoefficientValues pm_start;
  for (const auto& s : all) pm_start[s.name] = s.default_value;
  pm.fixed = pm_start;  // a coefficient held: the value stage 1 holds it at
  SearchOptions po = options;
  po.max_evaluations = o.point_mass_evaluations;
  po.threads = 1;  // milliseconds each
  po.simulations = nullptr;  // nor counted in the fit's progress, which counts the soft ball's runs
  po.target_rms_m = 0;
  // Never more coefficients than heights: restitution, then its slope, then drag.
  const size_t heights = soft.recorded_m.size();
  std::vector<CoefficientSpec> free;
  auto hold = [&](const CoefficientSpec& s, HeldCoefficient::Kind kind, double value, double sigma,
                  const std::string& why, const std::string& bound = "") {
    pm.fixed[s.name] = pm_start[s.name] = value;
    out.held.push_back({SoftLawName(s.name), kind, value, sigma, why, bound});
  };
  const double sse_sigma = o.measurement_sigma_m * o.measurement_sigma_m;
  auto sse = [&](const SearchResult& r) {
    return r.failure.empty() ? r.rms_m * r.rms_m * static_cast<double>(heights) : INFINITY;
  };
  // Stage 1 with coefficient s held at value, the others in `free` searched.
  auto fit_held_at = [&](const CoefficientSpec& s, double value) {
    FitProblem q = pm;
    q.free.clear();
    for (const auto& f : free)
      if (f.name != s.name) q.free.push_back(f);
    q.fixed[s.name] = value;
    CoefficientValues start = pm_start;
    start[s.name] = value;
    return LeastSquaresSearch(q, start, po);
  };
  // Where the heights leave the drag at the preset's value, the first fall's duration
  // measures it, if it tells it from the preset's (beyond 2 sigma) and the heights fit it as
  // well (else the fall was not from rest at that apex time: a push, a late release).
  // at_preset: stage 1 with s at the preset's value, when already run.
  auto hold_preset = [&](const CoefficientSpec& s, const std::string& why, const SearchResult* at_preset) {
    if (s.name == "drag_coefficient") {
      const TimedDrag timed = DragFromFall(soft, point_mass, pm_start, s);
      bool fits = std::isfinite(timed.sigma) && std::abs(timed.value - s.default_value) > 2 * timed.sigma;
      if (fits) {
        const double preset_sse = sse(at_preset ? *at_preset : fit_held_at(s, s.default_value));
        const bool searched = std::any_of(free.begin(), free.end(), [&](const auto& f) { return f.name == s.name; });
        const size_t others = free.size() - (searched ? 1 : 0);
        const double dof = static_cast<double>(std::max<size_t>(1, heights - std::min(heights - 1, others)));
        fits = sse(fit_held_at(s, timed.value)) - preset_sse <= std::max(sse_sigma, preset_sse / dof);
      }
      if (fits) {
        hold(s, HeldCoefficient::Kind::kTimed, timed.value, timed.sigma,
             why + fmt::format("; timed by the first fall ({:.3g} s from {:.3g} m) instead of the ball preset's {:.3g}",
                               soft.start_fall_s, soft.simulation.drop_height_m, s.default_value));
        return;
      }
    }
    hold(s, HeldCoefficient::Kind::kPreset, s.default_value, 0, why);
  };
  for (const auto& s : all) {
    if (free.size() < std::max<size_t>(1, heights))
      free.push_back(s);
    else
      hold_preset(s,
                  "not identifiable from " + std::to_string(heights) + " height" + (heights == 1 ? "" : "s") +
                      " (more coefficients than heights)",
                  nullptr);
  }
  for (;;) {
    pm.free = free;
    out.point_mass = LeastSquaresSearch(pm, pm_start, po);
    if (free.size() <= 1 || out.point_mass.jacobian.empty()) break;
    SensitivityOptions so;
    so.max_sigma_fraction = o.max_sigma_fraction;
    const auto est = EstimateUncertainty(free, out.point_mass.values, out.point_mass.jacobian,
                                         out.point_mass.rms_m, o.measurement_sigma_m, so);
    // The one to hold: drag before the slope; restitution is always fitted.
    int j = static_cast<int>(free.size()) - 1;
    for (; j >= 1; --j) {
      const CoefficientSpec& s = free[j];
      const double v = out.point_mass.values.at(s.name);
      const double range = s.upper - s.lower;
      const bool at_lower = v <= s.lower + o.pinned_fraction * range;
      const bool at_upper = v >= s.upper - o.pinned_fraction * range;
      if (!est[j].identifiable) {
        // A flat direction: the preset's value if it fits as well, else the data's.
        const SearchResult r = fit_held_at(s, s.default_value);
        // As well: within one sigma of the heights, or of the fit's own residual where that
        // is larger (heights the point mass cannot follow to their measurement).
        const double dof = static_cast<double>(std::max<size_t>(1, heights - std::min(heights - 1, free.size())));
        const double level = std::max(sse_sigma, sse(out.point_mass) / dof);
        const double worse = sse(r) - sse(out.point_mass);
        const std::string why = "not identifiable from these bounces (" + est[j].note + ")";
        if (r.failure.empty() && worse <= level)
          hold_preset(s, why + "; the ball preset's value fits as well", &r);
        else
          hold(s, HeldCoefficient::Kind::kData, v, 0,
               why + fmt::format("; the ball preset's value {:.3g} fits worse ({:.3g} mm RMS against {:.3g} "
                                 "mm): the data's value is kept",
                                 s.default_value, 1000 * r.rms_m, 1000 * out.point_mass.rms_m));
        break;
      }
      if (at_lower || at_upper) {
        const double bound = at_lower ? s.lower : s.upper;
        const std::string side = at_lower ? "lower" : "upper";
        hold(s, HeldCoefficient::Kind::kBound, bound, est[j].sigma,
             fmt::format("at its {} bound {:.3g}, where the bounces put it", side, bound), side);
        break;
      }
    }
    if (j < 1) break;
    free.erase(free.begin() + j);
  }
  const double e0 = out.point_mass.values.at("restitution");
  const double k = out.point_mass.values.at("restitution_per_mps");
  const double cd = out.point_mass.values.at("drag_coefficient");

  // Stage 2: the soft ball's law near stage 1's curve.
  FitProblem sp = soft;
  sp.segments = o.segments;
  sp.fixed = WithRestitutionLaw(soft.fixed, e0, k, cd);
  sp.free.clear();
  for (const auto& f : free) {
    if (f.name == "restitution")
      sp.free.push_back(Narrowed(*soft.model, "rebound_restitution", e0 - o.restitution_range,
                                 e0 + o.restitution_range));
    else if (f.name == "restitution_per_mps")
      sp.free.push_back(Narrowed(*soft.model, "rebound_restitution_per_mps", k - o.slope_range,
                                 k + o.slope_range));
    else if (f.name == "drag_coefficient")
      sp.free.push_back(Narrowed(*soft.model, "drag", cd / o.drag_factor, cd * o.drag_factor));
  }
  SearchOptions so = options;
  so.max_evaluations = o.max_evaluations;
  LeastSquaresOptions ls;
  ls.fd_step = o.fd_step;
  ls.max_iterations = 8;
  ls.min_relative_gain = 1e-3;
  out.soft = LeastSquaresSearch(sp, sp.fixed, so, ls);
  out.soft.method = "restitution-curve";
  return out;
}

}  // namespace bouncefit
