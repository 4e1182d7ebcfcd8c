#include "detect/heard_peaks.h"

#include <cmath>

namespace bouncefit {

std::vector<ApexOnArc> PlaceApexesOnHeardArcs(const std::vector<double>& apex_t_s,
                                              const FusionResult& fused) {
  std::vector<ApexOnArc> out(apex_t_s.size());
  std::vector<int> nearest(fused.flights.size(), -1);  // per arc: its nearest seen apex
  for (size_t p = 0; p < apex_t_s.size(); ++p) {
    const double t = apex_t_s[p];
    for (size_t f = 0; f < fused.flights.size(); ++f) {
      const HeardFlight& fl = fused.flights[f];
      const double start = fused.impacts[fl.from].t_s;
      if (!(t > start && t < start + fl.flight_s)) continue;
      out[p].flight = static_cast<int>(f);
      int& n = nearest[f];
      if (n < 0 || std::abs(t - fl.apex_t_s) < std::abs(apex_t_s[n] - fl.apex_t_s)) n = static_cast<int>(p);
      break;
    }
  }
  for (size_t p = 0; p < out.size(); ++p)
    out[p].duplicate = out[p].flight >= 0 && nearest[out[p].flight] != static_cast<int>(p);
  return out;
}

}  // namespace bouncefit
