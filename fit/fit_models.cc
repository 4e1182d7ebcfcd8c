#include "fit/fit_models.h"

#include <stdexcept>

#include "fit/point_mass_model.h"
#include "fit/soft_ball_model.h"

namespace bouncefit {

std::string FitModelNames() { return "bullet-softbody, point-mass"; }

std::unique_ptr<BallModel> MakeFitModel(const std::string& name, const BallPreset& ball) {
  if (name == "bullet-softbody" || name == "soft") return std::make_unique<SoftBallModel>(ball);
  if (name == "point-mass") return std::make_unique<PointMassModel>(ball);
  throw std::invalid_argument("unknown model '" + name + "' (known: " + FitModelNames() + ")");
}

void ConfigureSessionForModel(const BallModel& model, const BallPreset& ball,
                              FitSessionConfig* config) {
  (void)ball;
  if (const auto* soft = dynamic_cast<const SoftBallModel*>(&model)) {
    config->time_step_s = soft->config().time_step_s;
    config->iterations = soft->config().position_iterations;
  }
}

}  // namespace bouncefit
