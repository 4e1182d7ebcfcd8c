#pragma once
// The apex of a ballistic arc from samples around its top: a least-squares parabola
// through the arc, not the top sample (pixel noise dominates the half-frame
// timing error). Shared by the bounce detector (video) and the models (simulation), so
// simulated and recorded heights are measured the same way.
#include <vector>

namespace bouncefit {

struct ArcApex {
  bool ok = false;          // false: fewer than 3 samples, or the arc opens upward
  double t = 0;             // apex time, same unit as the input times
  double height = 0;        // apex height, same unit as the input heights
  double curvature = 0;     // 2nd derivative of height, height units / time^2 (< 0 for an arc)
  double rms_residual = 0;  // of the fit, height units
};

// Heights are "up is positive". Times need not be evenly spaced. Samples are centred on
// their mean time internally, so absolute times (microseconds since epoch) are fine.
ArcApex FitArcApex(const std::vector<double>& t, const std::vector<double>& height);

}  // namespace bouncefit
