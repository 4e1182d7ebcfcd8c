#pragma once
// What a fit session needs to know of the model it fits.
#include "fit/fit_session.h"
#include "model/ball_model.h"
#include "model/ball_preset.h"

namespace bouncefit {

// Fills what a session needs to know about the model: the time step and iterations the
// coefficients hold for, and the warm start (the soft-body model's preset table for this
// ball, when it has one).
void ConfigureSessionForModel(const BallModel& model, const BallPreset& ball,
                              FitSessionConfig* config);

}  // namespace bouncefit
