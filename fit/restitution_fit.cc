#include "fit/restitution_fit.h"

#include <algorithm>
#include <cmath>
#include <sstream>

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

std::string Num(double v) {
  std::ostringstream o;
  o.precision(3);
  o << v;
  return o.str();
}

}  // namespace

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
  pm.fixed = pm_start;  // a coefficient held: the preset's value
  SearchOptions po = options;
  po.max_evaluations = o.point_mass_evaluations;
  po.threads = 1;  // milliseconds each
  po.target_rms_m = 0;
  // Never more coefficients than heights: restitution, then its slope, then drag.
  const size_t heights = soft.recorded_m.size();
  std::vector<CoefficientSpec> free;
  for (const auto& s : all) {
    if (free.size() < std::max<size_t>(1, heights)) {
      free.push_back(s);
    } else {
      out.held.push_back(SoftLawName(s.name));
      out.held_why.push_back("not identifiable from " + std::to_string(heights) + " height" +
                             (heights == 1 ? "" : "s") + " (more coefficients than heights)");
    }
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
    int hold = -1;
    std::string why;
    for (int j = static_cast<int>(free.size()) - 1; j >= 1 && hold < 0; --j) {
      const CoefficientSpec& s = free[j];
      const double v = out.point_mass.values.at(s.name);
      const double range = s.upper - s.lower;
      if (v <= s.lower + o.pinned_fraction * range || v >= s.upper - o.pinned_fraction * range) {
        hold = j;
        why = "pinned at its bound " + Num(v <= s.lower + o.pinned_fraction * range ? s.lower : s.upper);
      } else if (!est[j].identifiable) {
        hold = j;
        why = "not identifiable from these bounces (" + est[j].note + ")";
      }
    }
    if (hold < 0) break;
    out.held.push_back(SoftLawName(free[hold].name));
    out.held_why.push_back(why);
    free.erase(free.begin() + hold);
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
