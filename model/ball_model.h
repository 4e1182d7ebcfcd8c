#pragma once
// A simulated ball: coefficients in, bounce heights (and a trajectory) out.
//
// Implemented by the Bullet soft-body model and by the point-mass model; used by the
// fitters. Simulate() is const and thread-safe so that a fitter can run
// several evaluations in parallel on one model object.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace bouncefit {

// One tunable coefficient of a model, with the bounds a fitter must stay in.
struct CoefficientSpec {
  std::string name;         // says what it is: "linear_stiffness", "pressure", ...
  std::string unit;         // "" for dimensionless
  double default_value = 0;
  double lower = 0;         // inclusive bounds
  double upper = 0;
  bool discrete = false;    // integer-valued (mesh resolution, ...): round before use
  std::string description;  // one line, for --help and reports
};

using CoefficientValues = std::map<std::string, double>;

struct TrajectorySample {
  double t_s = 0;            // seconds since release
  double bottom_height_m = 0; // ball bottom above the floor, metres
  double center_height_m = 0; // centre above the floor, metres
  double width_height_ratio = 1;  // horizontal / vertical extent (1 for a point mass)
};

struct SimulationOptions {
  double drop_height_m = 1.0;   // ball bottom above the floor at release, metres
  double duration_s = 6.0;      // simulated time, at most
  double min_bounce_height_m = 0.01;  // stop once apexes fall below this
  // Stop once bounce max_bounces is measured (its arc closed by the next impact), 0: no
  // limit. A fit needs no more bounces than were recorded; heights 1..max_bounces are the
  // same as a longer run's. Models that are cheap anyway may ignore it.
  int max_bounces = 0;
  // The ball turned about the vertical at release, radians (a model with an orientation,
  // the soft ball's mesh, uses it; a point mass has none).
  double release_turn_rad = 0;
  bool record_trajectory = false;
  double trajectory_rate_hz = 120;    // sampling of the recorded trajectory
  // With the trajectory, a mesh model also keeps its surface at every trajectory sample
  // (what an animation of the ball plays; a point mass has none).
  bool record_surface = false;
};

// The ball's surface over a run: its triangles and, at every trajectory sample, where each
// of its vertices is (metres, the world's frame: y up, the floor at y = 0).
struct SurfaceRecording {
  std::vector<std::array<int, 3>> triangles;  // vertex indices, wound outward
  std::vector<std::vector<std::array<float, 3>>> positions_m;  // [sample][vertex]
};

struct SimulationResult {
  bool ok = false;
  std::string failure;                   // why not ok: "diverged (NaN) at t=0.41 s", ...
  std::vector<double> bounce_heights_m;  // apex heights (ball bottom), bounce 1, 2, ...
  std::vector<double> apex_times_s;      // their times since release
  std::vector<double> impact_times_s;
  std::vector<TrajectorySample> trajectory;  // when requested
  SurfaceRecording surface;                  // when requested, of a mesh model
  double simulated_time_s = 0;  // simulated time covered before the run stopped
  double wall_time_s = 0;
};

class BallModel {
 public:
  virtual ~BallModel() = default;
  virtual std::string name() const = 0;  // "bullet-softbody", "point-mass"
  virtual std::vector<CoefficientSpec> Coefficients() const = 0;
  // Missing coefficients take their defaults; unknown names are an error (ok = false).
  virtual SimulationResult Simulate(const CoefficientValues& values,
                                    const SimulationOptions& options) const = 0;
};

}  // namespace bouncefit
