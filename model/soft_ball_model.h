#pragma once
// The paper's ball: a Bullet (3.24, classic btSoftBody) soft body made from a TetGen
// tetrahedral sphere, dropped on a box floor. Coefficients in, trajectory and bounce heights
// out; see docs/MODEL.md for every coefficient, what Bullet does with it and how much it
// matters.
//
// Bounce heights are measured from the simulation as the detector measures them from a
// video: the ball's centre is sampled at the camera rate, impacts are the minima of that
// curve, and each apex is a least-squares parabola (FitArcApex) through the samples around
// the top of its arc. Heights are the ball's bottom (centre - radius) above the floor.
// The recorded trajectory gives the centre (of mass), the mesh's lowest point as the bottom
// and the width/height ratio of the mesh's extents (1 for the undeformed mesh).
//
// Simulate() is const and thread-safe: every call builds its own Bullet world; meshes come
// read-only from the TetGen cache. The same coefficients give the same heights to the last
// bit. A diverging run (NaN, explosion, ball through the floor, energy growth) is reported
// as ok = false with the reason, never a crash or a hang.
//
// The heights are chaotic in the coefficients: a change of a few parts per million moves the
// second and later bounces by percent (docs/MODEL.md). Fitters must treat
// them as noisy.
#include <string>
#include <vector>

#include "model/ball_model.h"
#include "model/ball_preset.h"
#include "model/bounce_measure.h"
#include "model/soft_ball_world.h"
#include "model/tetgen_mesh.h"

namespace bouncefit {

// The settings fixed per model (model/soft_ball_world.h) and where TetGen meshes come from.
struct SoftBallModelConfig : SoftBallWorldConfig {
  TetgenOptions tetgen;
};

class SoftBallModel : public BallModel {
 public:
  explicit SoftBallModel(BallPreset ball, SoftBallModelConfig config = {});

  std::string name() const override { return "bullet-softbody"; }
  std::vector<CoefficientSpec> Coefficients() const override;
  SimulationResult Simulate(const CoefficientValues& values,
                            const SimulationOptions& options) const override;

  const BallPreset& ball() const { return ball_; }
  const SoftBallModelConfig& config() const { return config_; }
  // Defaults for every coefficient, with `values` applied; "" or a one-line error
  // (unknown name, out of bounds, not a number) in *error.
  CoefficientValues Complete(const CoefficientValues& values, std::string* error) const;
  // The TetGen mesh these coefficients use (throws like GetTetMesh).
  std::shared_ptr<const TetMesh> Mesh(const CoefficientValues& values) const;

 private:
  BallPreset ball_;
  SoftBallModelConfig config_;
};

// Parses "name=value,name=value" (spaces allowed); throws std::invalid_argument.
CoefficientValues ParseCoefficientList(const std::string& text);

}  // namespace bouncefit
