#pragma once
// A ball's official bounce test (the federation's drop onto a hard surface, and the rebound
// it requires) and what it means for the restitution law: the impact speed of that drop and
// the range of e there, air drag included (docs/MODEL.md "The ball's own standard").
// A fitted ball's e at that speed beside the range tells a user at once when a scale, a
// clock or a ball is wrong (a softer floor than the test's gives less).
#include <optional>
#include <string>

#include "model/ball_preset.h"

namespace bouncefit {

struct BounceStandard {
  std::string body;      // "ITTF", "ITF", "FIBA", "FIFA"
  std::string surface;   // what the test drops onto: "steel", "concrete", ...
  double drop_m = 0;     // ball bottom above the surface at release
  double rebound_lo_m = 0, rebound_hi_m = 0;  // the rebound's apex, ball bottom, allowed range
  std::string measured;  // how the rule states it, e.g. "1.8 m to the bottom, 1.2-1.4 m to the top"
};

// The standard of a ball preset (none for wiffle, softball, airball: no drop test of theirs).
std::optional<BounceStandard> BounceStandardOf(const std::string& ball);

struct StandardRestitution {
  double impact_mps = 0;   // speed at the surface after the test's drop, with drag
  double e_lo = 0, e_hi = 0;  // restitution that gives the rebound range, with drag on the way up
};

// Quadratic drag F = 0.5 rho Cd A v^2 (the preset's Cd and size): a fall from rest through h
// ends at v^2 = (g/c)(1 - exp(-2 c h)), and a rise from u reaches H with u^2 = (g/c)(exp(2 c H) - 1),
// c = rho Cd A / (2 m).
StandardRestitution StandardRestitutionOf(const BounceStandard& standard, const BallPreset& ball,
                                          double g_mps2 = 9.81, double air_density_kgpm3 = 1.2);

}  // namespace bouncefit
