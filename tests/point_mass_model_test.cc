// The point-mass BallModel runs model/point_mass_drop's physics, and the quick fit recovers
// known restitution, speed dependence and drag from heights that physics produced.
#include <gtest/gtest.h>

#include <cmath>

#include "fit/fit_session.h"
#include "model/ball_preset.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"
#include "tests/point_mass_truth.h"

namespace bouncefit {
namespace {

std::vector<double> TruthHeights(const BallPreset& ball, double drop, int n) {
  const auto r = testing::PointMassTruth(ball, drop);
  std::vector<double> h;
  for (size_t i = 1; i < r.apex_heights_m.size() && static_cast<int>(h.size()) < n; ++i)
    if (r.apex_heights_m[i] >= 0.01) h.push_back(r.apex_heights_m[i]);
  return h;
}

TEST(PointMassModel, SameHeightsAsThePhysicsItWraps) {
  const auto ball = *FindBallPreset("wiffle");
  PointMassModel model(ball);
  SimulationOptions o;
  o.drop_height_m = 1.2;
  o.duration_s = 20;
  const auto r = model.Simulate({}, o);
  ASSERT_TRUE(r.ok) << r.failure;
  const auto truth = TruthHeights(ball, 1.2, 100);
  ASSERT_EQ(r.bounce_heights_m.size(), truth.size());
  // The model integrates with a 1 ms step, the renderer's physics with 0.1 ms: RK4 makes
  // the difference far below a nanometre.
  for (size_t i = 0; i < truth.size(); ++i) EXPECT_NEAR(r.bounce_heights_m[i], truth[i], 1e-9);
  // Apex times are since release and increasing.
  for (size_t i = 1; i < r.apex_times_s.size(); ++i) EXPECT_GT(r.apex_times_s[i], r.apex_times_s[i - 1]);
  EXPECT_NEAR(r.apex_times_s[0], std::sqrt(2 * 1.2 / 9.81) + std::sqrt(2 * truth[0] / 9.81), 0.05);
}

TEST(PointMassModel, CoefficientsChangeTheHeightsAndUnknownNamesFail) {
  PointMassModel model(*FindBallPreset("pingpong"));
  SimulationOptions o;
  const auto base = model.Simulate({}, o);
  const auto bouncier = model.Simulate({{"restitution", 0.95}}, o);
  const auto draggier = model.Simulate({{"drag_coefficient", 1.5}}, o);
  ASSERT_TRUE(base.ok && bouncier.ok && draggier.ok);
  EXPECT_GT(bouncier.bounce_heights_m[0], base.bounce_heights_m[0]);
  EXPECT_LT(draggier.bounce_heights_m[0], base.bounce_heights_m[0]);
  const auto bad = model.Simulate({{"linear_stiffness", 0.5}}, o);
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.failure.find("linear_stiffness"), std::string::npos);
}

// Truth different from the preset the fit starts from: the fit must move all three.
TEST(PointMassQuickFit, RecoversRestitutionSlopeAndDrag) {
  auto start = *FindBallPreset("pingpong");  // e 0.92, slope 0.005, Cd 0.47
  BallPreset truth = start;
  truth.restitution = 0.88;
  truth.restitution_per_mps = 0.012;
  truth.drag_coefficient = 0.80;
  const double drop = 1.5;
  const auto heights = TruthHeights(truth, drop, 12);
  ASSERT_GE(heights.size(), 10u);

  PointMassModel model(start);
  FitSession session(model, &model, {});
  session.Reset(0);
  session.AddPeak({0, 0, drop, 0.001, 0});
  for (size_t i = 0; i < heights.size(); ++i)
    session.AddPeak({0, static_cast<int>(i + 1), heights[i], 0.001, 0});
  const FitUpdate u = session.QuickUpdate();
  EXPECT_EQ(u.model, "point-mass");
  EXPECT_EQ(u.method, "least-squares");
  EXPECT_LT(u.residual_m, 2e-5);
  ASSERT_EQ(u.coefficients.size(), 3u);
  std::map<std::string, CoefficientEstimate> c;
  for (const auto& e : u.coefficients) c[e.name] = e;
  EXPECT_NEAR(c["restitution"].value, 0.88, 0.003);
  EXPECT_NEAR(c["restitution_per_mps"].value, 0.012, 0.001);
  EXPECT_NEAR(c["drag_coefficient"].value, 0.80, 0.05);
  // Twelve clean bounces determine all three; uncertainties are finite and cover the truth.
  for (const auto& [name, e] : c) {
    EXPECT_TRUE(e.identifiable) << name << ": " << e.note;
    EXPECT_GT(e.sigma, 0) << name;
  }
  EXPECT_LT(std::abs(c["restitution"].value - 0.88), 4 * c["restitution"].sigma + 1e-4);
  EXPECT_GT(u.evaluations, 3);
}

// One bounce cannot tell three coefficients apart: the fit matches it and says so.
TEST(PointMassQuickFit, OneBounceFlagsWhatItCannotDetermine) {
  const auto ball = *FindBallPreset("tennis");
  PointMassModel model(ball);
  FitSession session(model, &model, {});
  session.AddPeak({0, 0, 1.0, 0.001, 0});
  session.AddPeak({0, 1, 0.50, 0.001, 0});
  const FitUpdate u = session.QuickUpdate();
  EXPECT_LT(u.residual_m, 1e-4);
  EXPECT_FALSE(u.unidentified.empty());
  int identifiable = 0;
  for (const auto& e : u.coefficients) {
    identifiable += e.identifiable;
    if (!e.identifiable) {
      EXPECT_TRUE(std::isnan(e.sigma)) << e.name;
    }
  }
  EXPECT_LE(identifiable, 1);
}

}  // namespace
}  // namespace bouncefit
