#include "model/arc_apex.h"

#include <gtest/gtest.h>

#include <random>

namespace bouncefit {
namespace {

TEST(ArcApex, RecoversApexBetweenSamples) {
  // A 1 m arc sampled at 120 Hz with the apex between two samples.
  const double g = 9.81, t_apex = 1.2345, h_apex = 0.8;
  std::vector<double> t, h;
  for (int i = 140; i <= 156; ++i) {
    t.push_back(i / 120.0);
    h.push_back(h_apex - 0.5 * g * (t.back() - t_apex) * (t.back() - t_apex));
  }
  const ArcApex a = FitArcApex(t, h);
  ASSERT_TRUE(a.ok);
  EXPECT_NEAR(a.t, t_apex, 1e-9);
  EXPECT_NEAR(a.height, h_apex, 1e-9);
  EXPECT_NEAR(a.curvature, -g, 1e-6);
}

TEST(ArcApex, NoisySamplesBeatTheTopSample) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.002);
  const double g = 9.81, t_apex = 0.5;
  std::vector<double> t, h;
  double top = -1;
  for (int i = 40; i <= 80; ++i) {
    t.push_back(i / 120.0);
    h.push_back(1.0 - 0.5 * g * (t.back() - t_apex) * (t.back() - t_apex) + noise(rng));
    top = std::max(top, h.back());
  }
  const ArcApex a = FitArcApex(t, h);
  ASSERT_TRUE(a.ok);
  EXPECT_LT(std::abs(a.height - 1.0), std::abs(top - 1.0));
  EXPECT_NEAR(a.rms_residual, 0.002, 0.001);
}

TEST(ArcApex, RejectsTooFewOrUpwardOpening) {
  EXPECT_FALSE(FitArcApex({0, 1}, {0, 1}).ok);
  EXPECT_FALSE(FitArcApex({0, 1, 2}, {1, 0, 1}).ok);
  EXPECT_FALSE(FitArcApex({0, 1, 2}, {1, 2}).ok);
}

}  // namespace
}  // namespace bouncefit
