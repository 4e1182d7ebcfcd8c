#pragma once
// Bounce heights measured from a simulation as the detector measures them from a video, and
// the checks every Bullet ball model makes on a run's options and bounces. Standard C++ only:
// `fit --export` ships this file verbatim in the fitted_ball project (model/soft_ball_world.h).
#include <string>
#include <vector>

#include "model/ball_model.h"

namespace bouncefit {

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

}  // namespace bouncefit
