// The Bullet FEM ball (model/fem_ball_model.h, a trial measured and not adopted), with real tetgen meshes and
// real Bullet deformable-body runs. Short drops (0.3 m) on the default 93-node mesh keep
// each simulation well under a second of CPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "model/ball_preset.h"
#include "bench/trial/fem_ball_model.h"

namespace bouncefit {
namespace {

SimulationOptions ShortDrop() {
  SimulationOptions o;
  o.drop_height_m = 0.3;
  o.duration_s = 0.8;  // the fall (0.25 s), the first bounce and a little more
  return o;
}

const CoefficientValues kSoftPingpong{{"youngs_modulus", 1e4}, {"poisson_ratio", 0.3},
                                      {"damping", 0.0}, {"drag", 0.0}};

FemBallModel Pingpong(FemBallModelConfig cfg = {}) {
  return FemBallModel(*FindBallPreset("pingpong"), cfg);
}

TEST(FemBallModel, ReboundsFromStoredElasticEnergyAlone) {
  const SimulationResult r = Pingpong().Simulate(kSoftPingpong, ShortDrop());
  ASSERT_TRUE(r.ok) << r.failure;
  ASSERT_GE(r.bounce_heights_m.size(), 1u);
  // No artificial force: the ball must come back up, and not above where it fell from.
  EXPECT_GT(r.bounce_heights_m[0], 0.2 * 0.3);
  EXPECT_LT(r.bounce_heights_m[0], 0.3);
  // It fell as a body falls (no drag): impact after sqrt(2 h / g) = 0.247 s.
  ASSERT_GE(r.impact_times_s.size(), 1u);
  EXPECT_NEAR(r.impact_times_s[0], std::sqrt(2 * 0.3 / 9.81), 0.02);
}

TEST(FemBallModel, SquashesOnImpactAndStartsRound) {
  SimulationOptions o = ShortDrop();
  o.record_trajectory = true;
  const SimulationResult r = Pingpong().Simulate(kSoftPingpong, o);
  ASSERT_TRUE(r.ok) << r.failure;
  ASSERT_FALSE(r.trajectory.empty());
  EXPECT_NEAR(r.trajectory.front().width_height_ratio, 1, 1e-6);
  double widest = 0;
  for (const auto& s : r.trajectory) widest = std::max(widest, s.width_height_ratio);
  EXPECT_GT(widest, 1.02);  // a soft ball flattens on the floor
  EXPECT_LT(widest, 3);
}

TEST(FemBallModel, MaterialDampingLowersTheRebound) {
  const FemBallModel m = Pingpong();
  CoefficientValues damped = kSoftPingpong;
  damped["damping"] = 1e-3;
  const SimulationResult elastic = m.Simulate(kSoftPingpong, ShortDrop());
  const SimulationResult lossy = m.Simulate(damped, ShortDrop());
  ASSERT_TRUE(elastic.ok && lossy.ok) << elastic.failure << lossy.failure;
  ASSERT_FALSE(elastic.bounce_heights_m.empty());
  const double lossy_first = lossy.bounce_heights_m.empty() ? 0 : lossy.bounce_heights_m[0];
  EXPECT_LT(lossy_first, 0.8 * elastic.bounce_heights_m[0]);
}

TEST(FemBallModel, StepFollowsTheElasticWaveAndIsDeterministic) {
  const FemBallModel m = Pingpong();
  double crossing = 0;
  const double dt = m.TimeStep(kSoftPingpong, &crossing);
  EXPECT_NEAR(dt, m.config().courant * crossing, 1e-12);
  CoefficientValues stiffer = kSoftPingpong;
  stiffer["youngs_modulus"] = 4e4;  // wave speed x2: half the crossing time
  double stiffer_crossing = 0;
  m.TimeStep(stiffer, &stiffer_crossing);
  EXPECT_NEAR(stiffer_crossing, crossing / 2, 1e-9 * crossing);

  const SimulationResult a = m.Simulate(kSoftPingpong, ShortDrop());
  const SimulationResult b = Pingpong().Simulate(kSoftPingpong, ShortDrop());
  ASSERT_TRUE(a.ok && b.ok);
  EXPECT_EQ(a.bounce_heights_m, b.bounce_heights_m);
}

TEST(FemBallModel, AStepPastTheStabilityLimitIsAFailedRunNotACrash) {
  FemBallModelConfig cfg;
  cfg.courant = 4;  // explicit elastic forces: unstable past ~1 (docs/journal/fem-trial.md)
  const SimulationResult r = Pingpong(cfg).Simulate(kSoftPingpong, ShortDrop());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("diverged"), std::string::npos) << r.failure;
}

TEST(FemBallModel, BadCoefficientsAreOneLineErrors) {
  const FemBallModel m = Pingpong();
  const SimulationResult unknown = m.Simulate({{"linear_stiffness", 0.5}}, ShortDrop());
  EXPECT_FALSE(unknown.ok);
  EXPECT_NE(unknown.failure.find("unknown coefficient 'linear_stiffness'"), std::string::npos);
  const SimulationResult outside = m.Simulate({{"poisson_ratio", 0.5}}, ShortDrop());
  EXPECT_FALSE(outside.ok);
  EXPECT_NE(outside.failure.find("outside"), std::string::npos);
  EXPECT_EQ(outside.failure.find('\n'), std::string::npos);
  SimulationOptions bad = ShortDrop();
  bad.drop_height_m = -1;
  EXPECT_FALSE(m.Simulate(kSoftPingpong, bad).ok);
}

}  // namespace
}  // namespace bouncefit
