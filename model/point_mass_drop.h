#pragma once
// A ball dropped from rest as a point mass: gravity, quadratic air drag and a coefficient
// of restitution that may depend on the impact speed. The ground truth of `bouncefit synth`
// and the core of the point-mass BallModel.
//
// Integration: classic RK4 with a fixed small step; the impact inside a step is found by
// bisection on the step length (each trial is one RK4 step from the step's start), so
// impact times are exact to ~1e-12 s. Between integration knots the trajectory is a cubic
// Hermite interpolant of height and velocity (4th-order accurate), so it can be sampled
// densely at any time.
#include <vector>

#include "model/ball_preset.h"

namespace bouncefit {

struct PointMassDropConfig {
  BallPreset ball;                  // diameter, mass, restitution e(v), drag coefficient
  double drop_height_m = 1.0;       // ball bottom above the floor at release, metres (>= 0)
  double hold_s = 0;                // the ball is held still this long before release, s
  // Vertical speed at release, m/s, up positive (0: dropped from rest; > 0: thrown up, the
  // throw's apex is then apex [0]; < 0: thrown down).
  double launch_speed_mps = 0;
  double g_mps2 = 9.81;             // gravitational acceleration, m/s^2
  double air_density_kgpm3 = 1.2;   // rho of the drag force 0.5 rho Cd A v^2, kg/m^3
  bool drag = true;                 // false: no air drag at all (vacuum)
  double end_time_s = 10;           // simulate up to this time (same clock as hold_s), s
  // A rebound is followed while its drag-free apex v^2/(2g) reaches this; below it the
  // ball is at rest on the floor from that impact on.
  double min_apex_height_m = 0.002;
  double dt_s = 1e-4;               // RK4 step, s
};

// Height is the ball bottom above the floor (metres, up positive); velocity is up positive.
struct PointMassState {
  double height_m = 0;
  double velocity_mps = 0;
};

struct PointMassDropResult {
  // All times are on the config's clock: the hold starts at 0, release is at hold_s.
  double release_time_s = 0;
  std::vector<double> impact_times_s;    // every floor contact, in order
  std::vector<double> impact_speeds_mps; // speed just before each impact
  std::vector<double> restitutions;      // e(v) applied at each impact
  // Apexes: [0] is the release (time release_time_s, height drop_height_m), or the top of
  // the throw when launched upwards; [k] the apex
  // of the flight after impact k-1. A flight cut by end_time_s before its apex has none.
  std::vector<double> apex_times_s;
  std::vector<double> apex_heights_m;
  bool comes_to_rest = false;  // the ball lies on the floor from rest_time_s on
  double rest_time_s = 0;
  double end_time_s = 0;       // integration stopped here; At() holds the last state after

  // Dense sampling anywhere: before release the ball is held at the drop height; after
  // end_time_s (or rest) the last state holds. At an impact time, returns the rebound.
  PointMassState At(double t_s) const;

  struct Knot {
    double t, h, v, a;  // time, height, velocity, acceleration
  };
  std::vector<Knot> knots;  // integration knots; an impact appears twice (in, out)
};

// Throws std::invalid_argument with a one-line message for invalid configs (negative
// height, non-positive mass or diameter, ...).
PointMassDropResult SimulatePointMassDrop(const PointMassDropConfig& config);

}  // namespace bouncefit
