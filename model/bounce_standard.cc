#include "model/bounce_standard.h"

#include <cmath>
#include <numbers>

namespace bouncefit {

std::optional<BounceStandard> BounceStandardOf(const std::string& ball) {
  // Sources: docs/MODEL.md "The ball's own standard".
  if (ball == "pingpong") return BounceStandard{"ITTF", "steel", 0.305, 0.240, 0.260, "305 mm onto a steel block, 240-260 mm"};
  if (ball == "tennis") return BounceStandard{"ITF", "concrete", 2.54, 1.35, 1.47, "254 cm onto concrete, 135-147 cm"};
  // FIBA: dropped from 1.8 m measured to the ball's bottom, rebound 1.2-1.4 m measured to its
  // top: 0.239 m less to its bottom.
  if (ball == "basketball")
    return BounceStandard{"FIBA", "the playing floor", 1.8, 1.2 - 0.239, 1.4 - 0.239,
                          "1.8 m to the ball's bottom, 1.2-1.4 m to its top"};
  if (ball == "football") return BounceStandard{"FIFA Quality", "steel", 2.0, 1.25, 1.55, "2 m onto steel at 20 C, 1.25-1.55 m"};
  return std::nullopt;
}

StandardRestitution StandardRestitutionOf(const BounceStandard& s, const BallPreset& ball, double g,
                                          double rho) {
  const double area = std::numbers::pi * ball.radius_m() * ball.radius_m();
  const double c = ball.mass_kg > 0 ? rho * ball.drag_coefficient * area / (2 * ball.mass_kg) : 0;
  auto fall_speed = [&](double h) {
    return c > 1e-12 ? std::sqrt(g / c * (1 - std::exp(-2 * c * h))) : std::sqrt(2 * g * h);
  };
  auto rise_speed = [&](double h) {
    return c > 1e-12 ? std::sqrt(g / c * std::expm1(2 * c * h)) : std::sqrt(2 * g * h);
  };
  StandardRestitution r;
  r.impact_mps = fall_speed(s.drop_m);
  r.e_lo = rise_speed(s.rebound_lo_m) / r.impact_mps;
  r.e_hi = rise_speed(s.rebound_hi_m) / r.impact_mps;
  return r;
}

}  // namespace bouncefit
