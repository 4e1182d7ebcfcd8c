#pragma once
// The fitted ball as a glTF 2.0 binary (.glb) that Blender, Maya, Houdini, Unity, Godot and
// web viewers import: the ball dropped from a height and simulated, its surface keyed per
// sample (translation, rotation where it turns, deformation as morph targets with keyed
// weights: fit/ball_animation.h), on a floor plane. Metres, y up, the floor at y = 0, time
// in real seconds since the ball starts at rest at the drop height (a run's fit: its start
// apex, extras.fit.start). Written with tinygltf (Debian's libtinygltf-dev).
//
// Nodes: `floor`, `fitted_ball` and, given a recorded track, `recorded_ball` (the tracked
// ball on the same clock, beside the fitted one). docs/FORMATS.md "fitted_ball.glb".
#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

#include "fit/ball_animation.h"
#include "model/ball_model.h"
#include "model/ball_preset.h"

namespace bouncefit {

// A tracked ball on the simulation's clock.
struct RecordedTrack {
  std::vector<double> t_s;              // real s since the simulated ball's start
  std::vector<double> bottom_height_m;  // ball bottom above the floor, m
  std::vector<double> horizontal_m;     // horizontal position, m (empty: none)
};

struct FittedBallGltfOptions {
  double rate_hz = 120;  // keys per second (at least the clip's frame rate)
  double duration_s = 0;  // simulated time at most, s (0: long enough for the drop)
  double min_bounce_height_m = 0.005;  // the animation ends once the bounces are lower
  BallAnimationOptions animation;
};

// What was written, for messages and tests.
struct FittedBallGltf {
  std::filesystem::path path;
  size_t bytes = 0;
  size_t keys = 0;
  size_t vertices = 0;
  size_t morph_targets = 0;
  bool rotation = false;
  double max_error_m = 0;  // largest distance of a played vertex from the simulated one
  double max_deformation_m = 0;
  SimulationResult simulation;  // the drop that was animated
};

// Drops the ball with these coefficients from drop_height_m (its bottom above the floor, m),
// animates it and writes `path`. `extras` (a JSON object: the ball, the fit, the clip) go
// into the asset's extras, with the animation's own figures added. Throws
// std::runtime_error when the ball diverges or the file cannot be written.
FittedBallGltf WriteFittedBallGltf(const std::filesystem::path& path, const BallModel& model,
                                   const BallPreset& ball, const CoefficientValues& values,
                                   double drop_height_m, const nlohmann::json& extras,
                                   const RecordedTrack* recorded = nullptr,
                                   const FittedBallGltfOptions& options = {});

// The recorded ball stands this far beside the fitted one (+x), m: side by side, neither
// hides the other.
double RecordedBallOffsetM(const BallPreset& ball);

}  // namespace bouncefit
