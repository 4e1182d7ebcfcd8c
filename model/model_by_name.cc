#include "model/model_by_name.h"

#include <stdexcept>

#include "model/point_mass_model.h"
#include "model/soft_ball_model.h"

namespace bouncefit {

std::string BallModelNames() { return "bullet-softbody, point-mass"; }

std::unique_ptr<BallModel> MakeBallModel(const std::string& name, const BallPreset& ball) {
  if (name == "bullet-softbody" || name == "soft") return std::make_unique<SoftBallModel>(ball);
  if (name == "point-mass") return std::make_unique<PointMassModel>(ball);
  throw std::invalid_argument("unknown model '" + name + "' (known: " + BallModelNames() + ")");
}

}  // namespace bouncefit
