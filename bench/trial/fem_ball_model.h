#pragma once
// A ball as a Bullet 3.24 *deformable* body (a trial kept for its measurements): the TetGen sphere of the
// classic model (model/tetgen_mesh.h) simulated by btDeformableMultiBodyDynamicsWorld with a
// Neo-Hookean elastic force, so its coefficients are the ones an engineer knows: Young's
// modulus, Poisson's ratio and a strain-rate damping. No artificial rebound force: a bounce
// rises only from the elastic energy the ball stored while it was squashed.
//
// Bounce heights are measured as SoftBallModel measures them (MeasureBounces on the ball's
// bottom sampled at the camera rate; here interpolated between steps to the exact frame
// times, so that a change of step size moves no sample). Simulate() is const and
// thread-safe; a diverging run is ok = false with the reason. docs/journal/fem-trial.md
// gives the measured figures and the decision.
#include <memory>
#include <string>
#include <vector>

#include "model/ball_model.h"
#include "model/ball_preset.h"
#include "model/tetgen_mesh.h"

namespace bouncefit {

struct FemBallModelConfig {
  // Explicit elastic forces are stable only while a step is shorter than the time the
  // pressure wave (speed sqrt((lambda + 2 mu) / rho)) takes to cross the smallest element
  // (its shortest altitude). The step is that crossing time times `courant`, and never
  // longer than max_time_step_s. time_step_s > 0 fixes the step instead (for the bench).
  double courant = 0.5;
  double max_time_step_s = 1.0 / 480;
  double time_step_s = 0;
  // Bullet's backward-Euler solve of the whole momentum equation (setImplicit(true)); false
  // is Bullet's default: elastic forces explicit, damping implicit.
  bool implicit = false;
  // Bullet's contact treatment in the momentum solve: false (Bullet's default) adds Lagrange
  // multipliers (KKT preconditioner); true projects contact directions out (mass
  // preconditioner, strain limiting), as Bullet's volumetric demo does.
  bool use_projection = true;
  double gravity_mps2 = 9.81;
  double air_density_kgpm3 = 1.2;
  // Collision margin (contact distance) of the ball, as a fraction of its radius; the floor
  // is lowered by it so that the mesh surface touches y = 0.
  double margin_per_radius = 0.05;
  double sdf_voxel_per_radius = 0.25;
  double contact_erp = 0.06;  // btContactSolverInfo::m_deformable_erp (Bullet's default)
  double camera_rate_hz = 120;
  int apex_window_frames = 6;
  double max_wall_time_s = 60;
  TetgenOptions tetgen;

  std::string Validate() const;  // "" when valid
};

class FemBallModel : public BallModel {
 public:
  explicit FemBallModel(BallPreset ball, FemBallModelConfig config = {});

  std::string name() const override { return "bullet-fem"; }
  std::vector<CoefficientSpec> Coefficients() const override;
  SimulationResult Simulate(const CoefficientValues& values,
                            const SimulationOptions& options) const override;

  const BallPreset& ball() const { return ball_; }
  const FemBallModelConfig& config() const { return config_; }
  // Defaults with `values` applied; "" or a one-line error in *error.
  CoefficientValues Complete(const CoefficientValues& values, std::string* error) const;
  // The step Simulate() takes for these coefficients (s), and the explicit stability limit
  // it derives it from (the pressure wave's crossing time of the smallest element).
  double TimeStep(const CoefficientValues& values, double* crossing_time_s = nullptr) const;
  std::shared_ptr<const TetMesh> Mesh(const CoefficientValues& values) const;

 private:
  BallPreset ball_;
  FemBallModelConfig config_;
};

}  // namespace bouncefit
