#pragma once
// The point-mass ball as a BallModel ("point-mass"): model/point_mass_drop's physics with
// three coefficients, restitution at low speed, its loss per m/s of impact speed, and the
// quadratic drag coefficient. Mass and diameter come from the ball (never fitted). The
// quick physical estimate of the fit, and a fast model for tests.
#include "model/ball_model.h"
#include "model/ball_preset.h"

namespace bouncefit {

class PointMassModel : public BallModel {
 public:
  // Coefficient defaults are the ball's preset values.
  explicit PointMassModel(const BallPreset& ball, double g_mps2 = 9.81);

  std::string name() const override { return "point-mass"; }
  std::vector<CoefficientSpec> Coefficients() const override;
  SimulationResult Simulate(const CoefficientValues& values,
                            const SimulationOptions& options) const override;

  const BallPreset& ball() const { return ball_; }

 private:
  BallPreset ball_;
  double g_mps2_;
};

}  // namespace bouncefit
