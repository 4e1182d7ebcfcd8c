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
// second and later bounces by percent (docs/MODEL.md, "chaos floor"). Fitters must treat
// them as noisy.
#include <string>
#include <vector>

#include "model/ball_model.h"
#include "model/ball_preset.h"
#include "model/tetgen_mesh.h"

namespace bouncefit {

// Settings fixed per model: Bullet's damping and stiffness act per step and per iteration,
// so fitted coefficients hold for these values only. They are written next to every set of
// coefficients (model/presets/*.json, `simulate --json`).
struct SoftBallModelConfig {
  double time_step_s = 1.0 / 480;  // fixed Bullet step (4 per frame at 120 fps)
  int position_iterations = 4;     // btSoftBody::Config::piterations
  double gravity_mps2 = 9.81;      // soft bodies use btSoftBodyWorldInfo::m_gravity
  double air_density_kgpm3 = 1.2;  // btSoftBodyWorldInfo::air_density, for drag and lift
  // The collision margin (skin) of the soft body and the sparse-SDF voxel, as fractions of
  // the ball radius (Bullet's defaults, 0.25 m each, would float a 4 cm ball 25 cm high).
  double margin_per_radius = 0.25;
  double sdf_voxel_per_radius = 0.25;
  // Before the release the ball floats weightless this long with this damping (Config::kDP)
  // so that pressure and links reach their equilibrium shape.
  double settle_time_s = 0.1;
  double settle_damping = 0.05;
  // How bounce heights are measured (as the detector does on video).
  double camera_rate_hz = 120;
  int apex_window_frames = 6;  // samples each side of the top sample in the apex fit
  // Hard limits of one Simulate() call.
  double max_wall_time_s = 30;
  TetgenOptions tetgen;

  std::string Validate() const;  // "" when valid
};

// Bounce heights from camera-rate samples of the ball's bottom height, the way the detector
// does it: impacts are local minima of the sampled curve, each arc between two impacts
// gives one apex, fitted with FitArcApex through the arc's samples within window_frames of
// its top sample (samples at or below contact_height_m excluded). The release arc
// (bounce 0) is not reported. An unclosed last arc counts when it has at least
// window_frames samples after its top.
struct MeasuredBounces {
  std::vector<double> impact_times_s;
  std::vector<double> apex_times_s;
  std::vector<double> apex_heights_m;
};
MeasuredBounces MeasureBounces(const std::vector<double>& t_s, const std::vector<double>& bottom_m,
                               int window_frames, double contact_height_m = 0);

// Shared by the Bullet ball models (the classic soft ball and the FEM ball):
// why `options` cannot be simulated, or "" when they can;
std::string SimulationOptionsError(const SimulationOptions& options);
// the measured bounces down to options.min_bounce_height_m into `result` (heights, apex and
// impact times), or why they are a divergence: a bounce higher than the one before.
std::string TakeMeasuredBounces(const MeasuredBounces& measured, const SimulationOptions& options,
                                SimulationResult* result);

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
