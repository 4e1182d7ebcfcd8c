#include "fit/answer_gate.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "fit/fit_objective.h"
#include "fit/fit_timeline.h"
#include "fit/restitution_points.h"

namespace bouncefit {

std::string WhyNoAnswer(const FitUpdate& u, bool search_failed, double floor_m, double fraction) {
  if (u.recorded_m.empty()) return "";
  const double highest = *std::max_element(u.recorded_m.begin(), u.recorded_m.end());
  const double limit = std::max(floor_m, fraction * highest);
  if (search_failed) return u.warning;
  if (!u.restitution.drops_agree) return DropsDisagreement(u.restitution);
  if (!(u.residual_m <= limit))
    return fmt::format(
        "the fitted ball's heights are {:.1f} mm RMS from the recorded ones, more than {:.1f} mm (the "
        "larger of {:.1f} mm and {:.3g}% of the highest apex)",
        1000 * u.residual_m, 1000 * limit, 1000 * floor_m, 100 * fraction);
  return DropOutsideItsGate(u, floor_m, fraction);
}

std::string DropOutsideItsGate(const FitUpdate& u, double floor_m, double fraction) {
  const std::vector<FitDropSlice> slices = FitDropSlices(u);  // this drop's, then each kept drop's
  if (slices.size() < 2 || u.simulated_m.size() != u.recorded_m.size()) return "";
  for (size_t k = 0; k < slices.size(); ++k) {
    const auto from = u.recorded_m.begin() + static_cast<long>(slices[k].first);
    const std::vector<double> rec(from, from + static_cast<long>(slices[k].count));
    const auto sim_from = u.simulated_m.begin() + static_cast<long>(slices[k].first);
    const std::vector<double> sim(sim_from, sim_from + static_cast<long>(slices[k].count));
    if (rec.empty()) continue;
    const double rms = RmsResidual(rec, sim);
    const double limit = std::max(floor_m, fraction * *std::max_element(rec.begin(), rec.end()));
    if (rms <= limit) continue;
    const size_t number = k == 0 ? slices.size() : k;  // in time: the kept drops, then this one
    return fmt::format(
        "drop {} of {}: the fitted ball's heights are {:.1f} mm RMS from its recorded ones, more than {:.1f} mm "
        "(the larger of {:.1f} mm and {:.3g}% of its highest apex): one ball's coefficients do not describe "
        "every drop",
        number, slices.size(), 1000 * rms, 1000 * limit, 1000 * floor_m, 100 * fraction);
  }
  return "";
}

}  // namespace bouncefit
