#include "detect/apex_flight_check.h"

#include "detect/flight_model.h"

namespace bouncefit {
namespace {

// The height a flight of t seconds from (or to) its apex covers, m, and its uncertainty for a
// time uncertain by sigma_t (dh/dt is the speed there).
struct Side {
  double h = NAN, sigma = NAN;
};
// rising: the side before the apex (back in time from it, faster under drag).
Side FromTime(double t, bool rising, double sigma_t, const ApexFlightInput& in) {
  Side s;
  if (!(t > 0)) return s;
  const double tau = rising ? -t : t;
  s.h = FlightDrop(in.g_mps2, in.drag_per_m, tau);
  s.sigma = std::abs(FlightVelocityDown(in.g_mps2, in.drag_per_m, tau)) * sigma_t;
  return s;
}

bool Agree(double a, double sa, double b, double sb, double sigmas) {
  return std::abs(a - b) <= sigmas * std::hypot(sa, sb);
}

}  // namespace

ApexFlightResult CheckApexAgainstFlight(const ApexFlightInput& in) {
  ApexFlightResult r;
  const Side rise = FromTime(in.rise_s, true, in.time_sigma_s, in);
  const Side fall = FromTime(in.fall_s, false, in.time_sigma_s, in);
  if (!std::isfinite(rise.h)) return r;  // nothing to check against
  if (!std::isfinite(fall.h)) {
    r.flight_m = rise.h;
    r.flight_sigma_m = rise.sigma;
    if (!Agree(in.picture_m, in.picture_sigma_m, rise.h, rise.sigma, in.sigmas)) r.verdict = ApexVerdict::kHold;
    return r;
  }
  // Both sides: their mean, each side's time error shared by half.
  r.flight_m = 0.5 * (rise.h + fall.h);
  r.flight_sigma_m = 0.5 * std::hypot(rise.sigma, fall.sigma);
  if (Agree(in.picture_m, in.picture_sigma_m, r.flight_m, r.flight_sigma_m, in.sigmas)) return r;
  r.verdict = Agree(rise.h, rise.sigma, fall.h, fall.sigma, in.sigmas) ? ApexVerdict::kFlightHeight
                                                                      : ApexVerdict::kWithhold;
  return r;
}

}  // namespace bouncefit
