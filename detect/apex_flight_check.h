#pragma once
// An apex measured in the picture checked against the flight times around it before it is
// emitted. The picture measures a rebound's height over a floor line in pixels with a scale;
// the flight measures it with the clock alone: the rise from the impact before to the apex,
// the fall from the apex to the impact after (h = g t^2 / 2 each side, drag included; the
// whole flight g T^2 / 8). They disagree when the floor line under the apex is not where this
// arc touched the floor (a ball moving towards or away from the camera), when the scale is off,
// or when the arc is not one flight between two floor contacts (an impact missed, a contact
// taken off the floor). Each is judged beyond what the two measure (their uncertainties,
// three sigmas).
//
// What becomes of the apex:
//  - the picture agrees with the rise (live) or with the whole flight: emitted as measured;
//  - live, the picture disagrees with the rise: held until the impact after it is seen;
//  - both sides known and agreeing with each other (one flight from floor to floor) while the
//    picture disagrees: emitted with the flight's height, which needs no floor line and no
//    scale (only the clock);
//  - both sides known and disagreeing with each other and with the picture: withheld (no
//    measurement of this apex can be trusted).
#include <cmath>

namespace bouncefit {

enum class ApexVerdict { kAsMeasured, kHold, kFlightHeight, kWithhold };

struct ApexFlightInput {
  double picture_m = 0, picture_sigma_m = 0;  // the picture's height and its uncertainty
  double rise_s = NAN;   // impact before to the apex (NaN: not known)
  double fall_s = NAN;   // apex to the impact after (NaN: not seen yet)
  double time_sigma_s = 0;  // uncertainty of each of those two times
  double g_mps2 = 9.81;
  double drag_per_m = 0;    // quadratic drag, 1/m (the deceleration is k v^2)
  double sigmas = 3;        // disagreement beyond this many combined sigmas
};

struct ApexFlightResult {
  ApexVerdict verdict = ApexVerdict::kAsMeasured;
  double flight_m = NAN;        // the flight's height (both sides when known, else the rise)
  double flight_sigma_m = NAN;
};

ApexFlightResult CheckApexAgainstFlight(const ApexFlightInput& in);

}  // namespace bouncefit
