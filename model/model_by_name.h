#pragma once
// The ball models by name, for the CLI, the fit node and the benches.
#include <memory>
#include <string>

#include "model/ball_model.h"
#include "model/ball_preset.h"

namespace bouncefit {

// "bullet-softbody" (alias "soft") or "point-mass"; throws std::invalid_argument otherwise.
std::unique_ptr<BallModel> MakeBallModel(const std::string& name, const BallPreset& ball);
std::string BallModelNames();  // "bullet-softbody, point-mass"

}  // namespace bouncefit
