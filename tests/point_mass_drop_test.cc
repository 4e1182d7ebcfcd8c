// The point-mass drop follows the physics: drag-free bounces match the closed forms
// (apex ratio e^2, h = g dt^2 / 8, free-fall times), quadratic drag matches its closed-form
// fall and rise, and drag only ever loses energy.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "model/ball_preset.h"
#include "model/point_mass_drop.h"

namespace bouncefit {
namespace {

constexpr double kG = 9.81;

PointMassDropConfig Vacuum(double e, double drop = 1.0) {
  PointMassDropConfig c;
  c.ball = *FindBallPreset("tennis");
  c.ball.restitution = e;
  c.ball.restitution_per_mps = 0;
  c.drag = false;
  c.drop_height_m = drop;
  c.end_time_s = 20;
  return c;
}

TEST(PointMassDrop, WithoutDragApexRatioIsESquaredAndFlightTimesMatch) {
  const double e = 0.8, h0 = 1.3;
  const auto r = SimulatePointMassDrop(Vacuum(e, h0));
  ASSERT_GE(r.apex_heights_m.size(), 10u);
  EXPECT_DOUBLE_EQ(r.apex_heights_m[0], h0);
  EXPECT_NEAR(r.impact_times_s[0], std::sqrt(2 * h0 / kG), 1e-10);
  for (size_t k = 1; k < r.apex_heights_m.size(); ++k) {
    EXPECT_NEAR(r.apex_heights_m[k] / r.apex_heights_m[k - 1], e * e, 1e-9) << k;
    // The flight around apex k lasts from impact k-1 to impact k.
    if (k < r.impact_times_s.size()) {
      const double dt = r.impact_times_s[k] - r.impact_times_s[k - 1];
      EXPECT_NEAR(kG * dt * dt / 8, r.apex_heights_m[k], 1e-9) << k;
      EXPECT_NEAR(r.apex_times_s[k], 0.5 * (r.impact_times_s[k] + r.impact_times_s[k - 1]),
                  1e-9);
    }
  }
  for (size_t k = 0; k < r.restitutions.size(); ++k) EXPECT_DOUBLE_EQ(r.restitutions[k], e);
}

TEST(PointMassDrop, DenseSamplingMatchesTheParabola) {
  const double h0 = 0.9;
  auto c = Vacuum(0.7, h0);
  c.hold_s = 0.25;
  const auto r = SimulatePointMassDrop(c);
  EXPECT_DOUBLE_EQ(r.release_time_s, 0.25);
  EXPECT_DOUBLE_EQ(r.At(0.0).height_m, h0);  // held
  EXPECT_DOUBLE_EQ(r.At(0.1).velocity_mps, 0.0);
  const double t_imp = r.impact_times_s[0];
  for (double t = 0.25; t < t_imp; t += 0.00731) {
    const double s = t - 0.25;
    EXPECT_NEAR(r.At(t).height_m, h0 - kG * s * s / 2, 1e-10) << t;
    EXPECT_NEAR(r.At(t).velocity_mps, -kG * s, 1e-9) << t;
  }
  // Second flight: a parabola through both impacts with the rebound speed.
  const double v1 = 0.7 * kG * (t_imp - 0.25);
  for (double t = t_imp; t < r.impact_times_s[1]; t += 0.00517) {
    const double s = t - t_imp;
    EXPECT_NEAR(r.At(t).height_m, v1 * s - kG * s * s / 2, 1e-10) << t;
  }
  EXPECT_NEAR(r.At(t_imp).velocity_mps, v1, 1e-9);  // at the impact: the rebound
}

TEST(PointMassDrop, SpeedDependentRestitutionIsAppliedPerImpact) {
  auto c = Vacuum(0.9);
  c.ball.restitution_per_mps = 0.03;
  const auto r = SimulatePointMassDrop(c);
  ASSERT_GE(r.impact_speeds_mps.size(), 3u);
  for (size_t k = 0; k + 1 < r.apex_heights_m.size(); ++k) {
    const double v = r.impact_speeds_mps[k];
    const double e = 0.9 - 0.03 * v;
    EXPECT_DOUBLE_EQ(r.restitutions[k], e);
    EXPECT_NEAR(r.apex_heights_m[k + 1], (e * v) * (e * v) / (2 * kG), 1e-9);
  }
  // Slower impacts bounce back relatively higher.
  EXPECT_GT(r.apex_heights_m[3] / r.apex_heights_m[2], r.apex_heights_m[1] / r.apex_heights_m[0]);
}

TEST(PointMassDrop, QuadraticDragMatchesItsClosedForms) {
  PointMassDropConfig c;
  c.ball = *FindBallPreset("airball");  // light and large: strong drag
  c.ball.restitution_per_mps = 0;
  c.drop_height_m = 2.0;
  const auto r = SimulatePointMassDrop(c);
  const double area = std::numbers::pi * c.ball.radius_m() * c.ball.radius_m();
  const double k = 0.5 * 1.2 * c.ball.drag_coefficient * area / c.ball.mass_kg;
  const double vt = std::sqrt(kG / k);  // terminal speed
  // Fall from rest: h0 - h = vt^2/g ln cosh(g t / vt).
  const double t_fall = vt / kG * std::acosh(std::exp(c.drop_height_m * kG / (vt * vt)));
  EXPECT_NEAR(r.impact_times_s[0], t_fall, 1e-9);
  EXPECT_NEAR(r.impact_speeds_mps[0], vt * std::tanh(kG * t_fall / vt), 1e-8);
  // Rise from v0: apex = vt^2 / (2g) ln(1 + v0^2 / vt^2).
  const double v0 = c.ball.restitution * r.impact_speeds_mps[0];
  EXPECT_NEAR(r.apex_heights_m[1], vt * vt / (2 * kG) * std::log1p(v0 * v0 / (vt * vt)), 1e-9);
  // Rise time: vt/g atan(v0/vt).
  EXPECT_NEAR(r.apex_times_s[1] - r.impact_times_s[0], vt / kG * std::atan(v0 / vt), 1e-9);
}

TEST(PointMassDrop, DragLosesEnergy) {
  for (const auto& ball : BallPresets()) {
    PointMassDropConfig c;
    c.ball = ball;
    c.drop_height_m = 1.5;
    auto vac = c;
    vac.drag = false;
    const auto r = SimulatePointMassDrop(c);
    const auto v = SimulatePointMassDrop(vac);
    EXPECT_GT(r.impact_times_s[0], v.impact_times_s[0]) << ball.name;
    EXPECT_LT(r.impact_speeds_mps[0], std::sqrt(2 * kG * 1.5)) << ball.name;
    EXPECT_LT(r.apex_heights_m[1], v.apex_heights_m[1]) << ball.name;
    for (size_t k = 1; k < r.apex_heights_m.size() && k <= r.impact_speeds_mps.size(); ++k) {
      // Lost in flight: less than the rebound speed would carry in vacuum...
      const double vout = r.restitutions[k - 1] * r.impact_speeds_mps[k - 1];
      EXPECT_LT(r.apex_heights_m[k], vout * vout / (2 * kG)) << ball.name << " " << k;
      // ...and the next impact is slower than the fall from that apex would give.
      if (k < r.impact_speeds_mps.size()) {
        EXPECT_LT(r.impact_speeds_mps[k], std::sqrt(2 * kG * r.apex_heights_m[k]));
      }
    }
    // Energy (per unit mass) strictly decreases through the apexes.
    for (size_t k = 1; k < r.apex_heights_m.size(); ++k)
      EXPECT_LT(r.apex_heights_m[k], r.apex_heights_m[k - 1]);
  }
}

TEST(PointMassDrop, ComesToRestAndStaysThere) {
  PointMassDropConfig c;
  c.ball = *FindBallPreset("softball");
  c.drop_height_m = 1.0;
  c.min_apex_height_m = 0.005;
  const auto r = SimulatePointMassDrop(c);
  ASSERT_TRUE(r.comes_to_rest);
  EXPECT_DOUBLE_EQ(r.rest_time_s, r.impact_times_s.back());
  EXPECT_EQ(r.At(r.rest_time_s + 1).height_m, 0.0);
  EXPECT_EQ(r.At(r.rest_time_s + 1).velocity_mps, 0.0);
  // Every followed rebound had a drag-free apex above the threshold.
  for (size_t k = 0; k + 1 < r.impact_speeds_mps.size(); ++k) {
    const double v = r.restitutions[k] * r.impact_speeds_mps[k];
    EXPECT_GE(v * v / (2 * 9.81), c.min_apex_height_m);
  }
  // The heights stay >= 0 everywhere.
  for (double t = 0; t < r.rest_time_s + 0.5; t += 0.001) EXPECT_GE(r.At(t).height_m, -1e-12);
}

TEST(PointMassDrop, StopsAtEndTimeAndHandlesZeroHeight) {
  auto c = Vacuum(1.0);  // perfectly elastic: never rests
  c.end_time_s = 3;
  const auto r = SimulatePointMassDrop(c);
  EXPECT_FALSE(r.comes_to_rest);
  EXPECT_DOUBLE_EQ(r.end_time_s, 3);
  for (double h : r.apex_heights_m) EXPECT_NEAR(h, 1.0, 1e-9);
  c.drop_height_m = 0;
  const auto z = SimulatePointMassDrop(c);
  EXPECT_TRUE(z.comes_to_rest);
  EXPECT_TRUE(z.impact_times_s.empty());
  EXPECT_EQ(z.At(1).height_m, 0);
}

TEST(PointMassDrop, RejectsInvalidConfigs) {
  auto c = Vacuum(0.8);
  c.drop_height_m = -0.1;
  EXPECT_THROW(SimulatePointMassDrop(c), std::invalid_argument);
  c = Vacuum(0.8);
  c.ball.mass_kg = 0;
  EXPECT_THROW(SimulatePointMassDrop(c), std::invalid_argument);
  c = Vacuum(0.8);
  c.ball.diameter_m = -1;
  EXPECT_THROW(SimulatePointMassDrop(c), std::invalid_argument);
  c = Vacuum(0.8);
  c.g_mps2 = 0;
  EXPECT_THROW(SimulatePointMassDrop(c), std::invalid_argument);
}

}  // namespace
}  // namespace bouncefit
