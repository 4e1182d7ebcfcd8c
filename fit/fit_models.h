#pragma once
// What a fit session needs to know of the model it fits, and the models a fit runs.
#include <memory>
#include <string>

#include "fit/fit_session.h"
#include "model/ball_model.h"
#include "model/ball_preset.h"

namespace bouncefit {

// Fills what a session needs to know about the model: the time step and iterations the
// coefficients hold for, and the warm start (the soft-body model's preset table for this
// ball, when it has one).
void ConfigureSessionForModel(const BallModel& model, const BallPreset& ball,
                              FitSessionConfig* config);

// What a fit is set up with before its first peak: the ball (resolved by whoever reads it
// from the user), the model fitted and the session's settings.
struct FitSetup {
  BallPreset ball = ResolveBallPreset("pingpong");
  std::string model = "bullet-softbody";  // or "point-mass"
  FitSessionConfig session;
};

// The ball and the models of a fit: the model fitted, the point mass for the quick estimate
// after each bounce, and the session's settings for that model (ConfigureSessionForModel).
struct FitModels {
  BallPreset ball;
  std::unique_ptr<BallModel> model;
  std::unique_ptr<BallModel> quick;
  FitSessionConfig session;
};
// Throws std::invalid_argument for an unknown model.
FitModels MakeFitModels(const FitSetup& setup);

}  // namespace bouncefit
