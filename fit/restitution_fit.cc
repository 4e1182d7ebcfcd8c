#include "fit/restitution_fit.h"

#include <algorithm>

#include "fit/least_squares_search.h"

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
  FitProblem pm = soft;
  pm.model = &point_mass;
  pm.free = point_mass.Coefficients();
  pm.fixed.clear();
  pm.segments = false;  // not chaotic: its free drop is the best estimate
  pm.grid.clear();
  pm.safety = nullptr;  // a point mass cannot diverge
  pm.safety_simulations = 0;
  CoefficientValues pm_start;
  for (const auto& s : pm.free) pm_start[s.name] = s.default_value;
  SearchOptions po = options;
  po.max_evaluations = o.point_mass_evaluations;
  po.threads = 1;  // milliseconds each
  po.target_rms_m = 0;
  out.point_mass = LeastSquaresSearch(pm, pm_start, po);
  const double e0 = out.point_mass.values.at("restitution");
  const double k = out.point_mass.values.at("restitution_per_mps");
  const double cd = out.point_mass.values.at("drag_coefficient");

  // Stage 2: the soft ball's law near stage 1's curve.
  FitProblem sp = soft;
  sp.segments = o.segments;
  sp.fixed = WithRestitutionLaw(soft.fixed, e0, k, cd);
  sp.free = {Narrowed(*soft.model, "rebound_restitution", e0 - o.restitution_range,
                      e0 + o.restitution_range),
             Narrowed(*soft.model, "rebound_restitution_per_mps", k - o.slope_range,
                      k + o.slope_range),
             Narrowed(*soft.model, "drag", cd / o.drag_factor, cd * o.drag_factor)};
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
