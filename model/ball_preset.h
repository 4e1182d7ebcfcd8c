#pragma once
// The table of ball presets shared by every subcommand that takes --ball.
#include <optional>
#include <string>
#include <vector>

namespace bouncefit {

struct BallPreset {
  std::string name;
  std::string description;
  double diameter_m = 0;           // metres
  double mass_kg = 0;              // kilograms
  double restitution = 0;          // coefficient of restitution at low impact speed
  double restitution_per_mps = 0;  // e(v) = restitution - restitution_per_mps * v, v in m/s
  double drag_coefficient = 0;     // Cd of the quadratic air drag
  // Colour of the ball, BGR 0-255, used by synth and as the tracker's default guess.
  double color_bgr[3] = {0, 0, 0};

  double radius_m() const { return diameter_m / 2; }
  // Hops lower than this are contact chatter, not bounces: a tenth of the diameter, at least
  // 1 cm (a basketball's 1 cm hops; their apexes noisy by a millimetre).
  double chatter_hop_m() const { return diameter_m > 0.1 ? 0.1 * diameter_m : 0.01; }
  // Restitution at impact speed v (m/s), clamped to [0, 1].
  double RestitutionAt(double speed_mps) const;
};

const std::vector<BallPreset>& BallPresets();
// nullopt if no preset has that name.
std::optional<BallPreset> FindBallPreset(const std::string& name);
// "pingpong, wiffle, ..." for help texts and error messages.
std::string BallPresetNames();

// A preset with --diameter / --mass overrides applied (values <= 0 mean "keep").
// Throws std::invalid_argument with a one-line message for an unknown name.
BallPreset ResolveBallPreset(const std::string& name, double diameter_m = 0, double mass_kg = 0);

}  // namespace bouncefit
