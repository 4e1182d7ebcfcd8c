#pragma once
// A simulated ball's motion as an animation plays it (fit/fitted_ball_gltf.h writes it):
// the rest surface moved rigidly (its centre's translation and, where the ball turns, a
// rotation) and deformed by a few morph targets whose weights are keyed per sample. The
// targets are the principal components of the surface's deformation in the ball's own
// frame, as few as keep every played vertex within a tolerance of the simulated one.
#include <array>
#include <vector>

#include "model/ball_model.h"

namespace bouncefit {

struct BallAnimationOptions {
  // Morph targets are added until every vertex plays within this of the simulation, m.
  double tolerance_m = 0.25e-3;
  int max_targets = 32;
  // The rotation is keyed only where it moves a surface point more than this, m.
  double turn_tolerance_m = 0.02e-3;
};

struct BallAnimation {
  std::vector<double> t_s;  // key times, s since the release
  // The mesh around its centre (m, y up) and its triangles (wound outward): played with
  // every weight at its rest_weights value, it is the ball's rest shape.
  std::vector<std::array<float, 3>> base_m;
  std::vector<std::array<float, 3>> normals;  // unit, of the rest shape
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::array<float, 3>> translation_m;  // the centre, per key
  std::vector<std::array<float, 4>> rotation;       // unit quaternion (x, y, z, w) per key; empty: no turn
  std::vector<std::vector<std::array<float, 3>>> targets_m;  // morph targets' displacements, m
  std::vector<std::vector<float>> weights;  // [key][target], each in [0, 1]
  std::vector<float> rest_weights;          // [target]: the weights of the rest shape
  double max_error_m = 0;      // largest distance of a played vertex from the simulated one
  double max_deformation_m = 0;  // largest distance of a vertex from its rigidly moved rest place
  double max_turn_rad = 0;     // largest rotation from the rest orientation
};

// The animation of a recorded surface (SimulationResult::surface) sampled at t_s (its
// trajectory's times). Throws std::invalid_argument when the two disagree or it is empty.
BallAnimation AnimateSurface(const std::vector<double>& t_s, const SurfaceRecording& surface,
                             const BallAnimationOptions& options = {});

// A rigid sphere of this radius (a geodesic mesh of 10 f^2 + 2 vertices) whose centre is
// at centres_m at t_s: a ball with no recorded surface (a point mass, a tracked ball).
BallAnimation AnimateRigidSphere(const std::vector<double>& t_s,
                                 const std::vector<std::array<float, 3>>& centres_m,
                                 double radius_m, int frequency = 4);

}  // namespace bouncefit
