#include "model/ball_preset.h"

#include <algorithm>
#include <stdexcept>

namespace bouncefit {

double BallPreset::RestitutionAt(double speed_mps) const {
  return std::clamp(restitution - restitution_per_mps * speed_mps, 0.0, 1.0);
}

const std::vector<BallPreset>& BallPresets() {
  // Colours (BGR) are typical ones for synth: orange ping-pong, blue wiffle, yellow softball,
  // red toy ball, optic-green tennis ball.
  // Sizes and masses are the regulation or typical values; restitution is for a drop onto
  // a hard floor from about 1 m (e^2 is the first rebound ratio, drag aside).
  static const std::vector<BallPreset> presets = {
      {"pingpong", "table-tennis ball (ITTF 40 mm, 2.7 g)", 0.040, 0.0027, 0.92, 0.005, 0.47,
       {20, 120, 250}},
      {"wiffle", "plastic wiffle ball with holes", 0.072, 0.021, 0.62, 0.01, 0.60,
       {200, 160, 40}},
      {"softball", "12-inch softball", 0.097, 0.185, 0.42, 0.01, 0.40, {50, 235, 230}},
      {"airball", "air-filled children's toy ball", 0.150, 0.060, 0.80, 0.01, 0.47,
       {40, 40, 220}},
      {"tennis", "tennis ball (ITF)", 0.067, 0.058, 0.76, 0.005, 0.55, {60, 220, 200}},
      // Balls people film at home: FIBA size 7 (dropped from 1.8 m it must rebound to
      // 1.2-1.4 m) and FIFA size 5 (from 2 m onto steel, 1.2-1.65 m), below the drag crisis.
      {"basketball", "basketball (size 7, 0.239 m, 0.62 kg)", 0.239, 0.62, 0.84, 0.01, 0.47,
       {30, 90, 210}},
      {"football", "football (size 5, 0.22 m, 0.43 kg)", 0.22, 0.43, 0.84, 0.01, 0.47,
       {235, 235, 235}},
  };
  return presets;
}

std::optional<BallPreset> FindBallPreset(const std::string& name) {
  for (const auto& p : BallPresets())
    if (p.name == name) return p;
  return std::nullopt;
}

std::string BallPresetNames() {
  std::string names;
  for (const auto& p : BallPresets()) names += (names.empty() ? "" : ", ") + p.name;
  return names;
}

BallPreset ResolveBallPreset(const std::string& name, double diameter_m, double mass_kg) {
  auto preset = FindBallPreset(name);
  if (!preset)
    throw std::invalid_argument("unknown ball '" + name + "' (known: " + BallPresetNames() + ")");
  if (diameter_m > 0) preset->diameter_m = diameter_m;
  if (mass_kg > 0) preset->mass_kg = mass_kg;
  return *preset;
}

}  // namespace bouncefit
