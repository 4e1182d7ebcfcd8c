// The per-bounce updates on a point-mass drop with known truth: the quick estimate's
// coefficients grow with the bounces and recover the truth, the model's update moves its warm
// start towards it, a cancelled update keeps the warm start, and a final fit's Jacobian
// reorders what is searched first.
#include <gtest/gtest.h>

#include <atomic>

#include "fit/live_updates.h"
#include "model/ball_preset.h"
#include "model/point_mass_model.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

// A session's parts without the session: the softball preset fitted to a truth whose e is 0.50.
struct Live {
  explicit Live(int bounces) : model(*FindBallPreset("softball")), quick(*FindBallPreset("softball")) {
    config.max_evaluations_per_bounce = 20;
    BallPreset truth = *FindBallPreset("softball");
    truth.restitution = 0.50;  // preset 0.42: the fit has to move
    const auto h = testing::DropHeights(truth, 1.2, bounces);
    for (int b = 0; b <= bounces; ++b) drop.Add(b, {h[b], 0.001});
  }
  PointMassModel model, quick;
  FitSessionConfig config;
  RecordedDrop drop{0.01, 0.002};
  std::vector<KeptDrop> kept;
  DropProblems problems{model, config, drop, kept};
};

TEST(LiveUpdates, TheQuickEstimateTakesMoreCoefficientsWithMoreBounces) {
  Live two(2), five(5);
  LiveUpdates a(two.model, &two.quick, two.config, two.drop, two.problems);
  const LiveStepResult q2 = a.Quick();
  EXPECT_EQ(q2.problem.free.size(), 1u);  // restitution alone
  EXPECT_NEAR(q2.result.values.at("restitution"), 0.50, 0.01);
  LiveUpdates b(five.model, &five.quick, five.config, five.drop, five.problems);
  const LiveStepResult q5 = b.Quick();
  ASSERT_EQ(five.drop.fitted_heights().size(), 3u);  // the others under a centimetre
  EXPECT_EQ(q5.problem.free.size(), 2u);                 // and its speed dependence
  EXPECT_EQ(q5.problem.model, &five.quick);
  EXPECT_LT(RmsResidual(q5.problem.recorded_m, q5.result.simulated_m), 0.001);
  LiveUpdates none(five.model, nullptr, five.config, five.drop, five.problems);
  EXPECT_THROW(none.Quick(), std::logic_error);
}

TEST(LiveUpdates, AnUpdateMovesTheWarmStartAndACancelledOneKeepsIt) {
  Live l(4);
  LiveUpdates live(l.model, nullptr, l.config, l.drop, l.problems);
  EXPECT_DOUBLE_EQ(live.warm_start().at("restitution"), 0.42);
  std::atomic<int> simulations{0};
  CancelToken cancelled;
  cancelled.Cancel();
  const LiveStepResult c = live.Update(&cancelled, &simulations);
  EXPECT_TRUE(c.result.cancelled);
  EXPECT_EQ(c.result.evaluations, 0);
  EXPECT_DOUBLE_EQ(live.warm_start().at("restitution"), 0.42);
  const LiveStepResult u = live.Update(nullptr, &simulations);
  EXPECT_FALSE(u.result.cancelled);
  EXPECT_EQ(u.problem.free.size(), 1u);  // live_coefficients
  EXPECT_GT(u.result.evaluations, 0);
  EXPECT_LE(u.result.evaluations, 20);
  EXPECT_EQ(simulations.load(), u.result.evaluations);
  EXPECT_NEAR(live.warm_start().at("restitution"), 0.50, 0.01);
  EXPECT_LT(RmsResidual(u.problem.recorded_m, u.result.simulated_m), 0.01 * 1.2);
}

TEST(LiveUpdates, AFinalFitsJacobianPutsTheMostInfluentialFirst) {
  Live l(3);
  LiveUpdates live(l.model, nullptr, l.config, l.drop, l.problems);
  const std::vector<CoefficientSpec> free = l.model.Coefficients();
  EXPECT_EQ(live.order().front(), "restitution");  // the paper's priority
  SearchResult r;
  r.evaluations = 10;
  r.values = {{"restitution", 0.5}, {"restitution_per_mps", 0.01}, {"drag_coefficient", 0.3}};
  // Drag moves the heights most, then the slope.
  live.TakeFinal(r, {{0.01, 0.02, -0.05}, {0.005, 0.03, 0.04}}, free);
  EXPECT_EQ(live.order(), (std::vector<std::string>{"drag_coefficient", "restitution_per_mps", "restitution"}));
  EXPECT_DOUBLE_EQ(live.warm_start().at("drag_coefficient"), 0.3);
}

}  // namespace
}  // namespace bouncefit
