#pragma once
// The classic soft ball's Bullet world, in the one place it is written: the ball built from
// its tetrahedral mesh and configured from its coefficients, the floor, the settling before
// release, the rebound boost (an internal pre-tick callback), the fixed step and the bounce
// measurement. SoftBallModel runs it; `fit --export` ships this file and the few it includes
// verbatim in the fitted_ball project, so the exported ball is the fitted one by construction.
// Hence: Bullet 3.24 (classic btSoftBody) and the C++ standard library only, nothing else.
//
// Coefficients are read by name from the values map (every coefficient SoftBallModel
// lists, model/soft_ball_model.cc, with what each one does and its bounds).
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include <array>
#include <string>
#include <vector>

#include "model/ball_model.h"
#include "model/bounce_measure.h"
#include "model/rebound_kick.h"

namespace bouncefit {

// Settings fixed per model: Bullet's damping and stiffness act per step and per iteration,
// so fitted coefficients hold for these values only. They are written next to every set of
// coefficients (model/presets/*.json, `simulate --json`).
struct SoftBallWorldConfig {
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
  // The restitution law's rebound (model/rebound_kick.h): at the first contact step, else at
  // the deepest point of the contact (longer contact, impacts late by ~15 ms each).
  bool rebound_at_touch = true;
  // Hard limit of one run.
  double max_wall_time_s = 30;

  std::string Validate() const;  // "" when valid
};

// The tetrahedral sphere at unit radius, centred at the origin (TetGen's output).
struct SoftBallMesh {
  const std::vector<std::array<double, 3>>* nodes = nullptr;
  const std::vector<std::array<int, 4>>* tetras = nullptr;  // node indices
  const std::vector<std::array<int, 3>>* faces = nullptr;   // boundary, wound outward
};

// One ball: its size, mass, mesh and every coefficient value (complete: none missing).
struct SoftBallSpec {
  double radius_m = 0;
  double mass_kg = 0;
  SoftBallMesh mesh;
  CoefficientValues values;
};

// Sets up `info` (a soft-rigid world's btSoftBodyWorldInfo) for the ball: soft-body gravity,
// air density and the sparse-SDF voxel.
void ConfigureSoftBallWorldInfo(const SoftBallWorldConfig& cfg, double radius_m,
                                btSoftBodyWorldInfo* info);

// A new soft body (the caller owns it; not yet in a world): the mesh turned so that one
// surface vertex points straight down, then turned about the vertical by turn_rad, scaled to
// the radius, above the origin with its bottom bottom_height_m above y = 0; material, m_cfg
// fields, mass, pressure and volume conservation as the coefficients say. *rest_width_height (optional) gets the
// undeformed mesh's width/height ratio. Throws std::invalid_argument for a mesh that
// encloses no volume.
btSoftBody* CreateSoftBall(const SoftBallWorldConfig& cfg, const SoftBallSpec& ball,
                           btSoftBodyWorldInfo* info, double bottom_height_m, double turn_rad = 0,
                           double* rest_width_height = nullptr);

// The ball floats weightless for cfg.settle_time_s with strong damping, stepping `world`, so
// that pressure and links reach their equilibrium (an inflated ball is pre-stressed); then
// it is put back with its centre at centre_y and every node at rest.
void SettleSoftBall(const SoftBallWorldConfig& cfg, double centre_y, btSoftRigidDynamicsWorld* world,
                    btSoftBodyWorldInfo* info, btSoftBody* ball);

// The artificial rebound (not Bullet: the paper's 'artificial extra force', or the
// restitution law; model/rebound_kick.h), run as the world's internal pre-tick callback:
// once per contact episode every node gets an upward velocity change. Attach() after the
// settling; the world must then be stepped at cfg.time_step_s, one internal step per call.
class ReboundBoost {
 public:
  ReboundBoost(const SoftBallWorldConfig& cfg, const CoefficientValues& values);
  bool active() const { return law_.Active(); }
  // Sets the world's internal pre-tick callback (a world has one: it must be this).
  void Attach(btDynamicsWorld* world, btSoftBody* ball);
  // What the callback does, before each step: t_s is the time since Attach.
  void BeforeStep(btSoftBody* ball, double t_s);
  // The impacts seen so far, where the falling and rising arcs meet (s since Attach).
  std::vector<double> ImpactTimes() const { return contacts_.ImpactTimes(); }

 private:
  static void Tick(btDynamicsWorld* world, btScalar time_step);
  static ReboundLaw Law(const SoftBallWorldConfig& cfg, const CoefficientValues& values);
  double time_step_s_;
  ReboundLaw law_;
  ContactTracker contacts_;
  btSoftBody* ball_ = nullptr;
  long steps_ = 0;
};

// One drop as SoftBallModel::Simulate runs it: a world with the floor (its top face at
// y = -margin, so the mesh surface touches y = 0) and the ball released at rest with its
// bottom options.drop_height_m above the floor; bounce heights measured from camera-rate
// samples (MeasureBounces). A diverging run is ok = false with the reason.
SimulationResult SimulateSoftBallDrop(const SoftBallWorldConfig& cfg, const SoftBallSpec& ball,
                                      const SimulationOptions& options);

}  // namespace bouncefit
