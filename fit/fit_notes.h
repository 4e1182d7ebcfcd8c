#pragma once
// What a final fit means, said in plain lines for a person (run prints them after the final
// fit): the fitted restitution at 1 and 4 m/s, beside the ball's own bounce standard at its
// test's impact speed; the coefficients held at the preset's value and why; why a fit is no
// answer.
#include <string>
#include <vector>

#include "fit/fit_session.h"
#include "model/ball_preset.h"

namespace bouncefit {

// e(v) of the fitted law (rebound_restitution and _per_mps, or the point mass's restitution
// and restitution_per_mps), clamped to [0, 1]; NaN when the values hold no law.
double FittedRestitutionAt(const CoefficientValues& values, double speed_mps);

std::vector<std::string> FinalFitNotices(const FitUpdate& update, const BallPreset& ball);

}  // namespace bouncefit
