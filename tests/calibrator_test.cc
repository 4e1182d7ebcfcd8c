// The free-flight calibrator: scale, roll and floor from arcs of a point-mass drop with drag
// seen by a rolled camera; overrides and the diameter cross-check.
#include "detect/calibrator.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>

#include "tests/detect_sim.h"

namespace bouncefit {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// Splits a simulated clip into free-flight arcs at the true impacts, dropping frames whose
// exposure straddles an impact; arc 0 keeps the last 0.25 s of the hold.
CalibrationInput ArcsOf(const testing::SimClip& c, size_t max_arcs) {
  CalibrationInput in;
  in.radius_px = c.radius_px;
  const double frame = 1 / c.options.fps;
  const auto& imp = c.truth.impact_times_s;
  for (size_t j = 0; j < max_arcs && j < imp.size(); ++j) {
    FlightArcData arc;
    arc.held_before_apex = j == 0;
    const double begin = j == 0 ? c.truth.release_time_s - 0.25 : imp[j - 1];
    for (const auto& o : c.obs) {
      const double t = o.utime * 1e-6;
      if (!o.found || t < begin + frame / 2 || t > imp[j] - frame / 2) continue;
      arc.samples.push_back({t, o.cx, o.cy});
    }
    in.arcs.push_back(arc);
  }
  in.utime = c.obs.back().utime;
  return in;
}

testing::SimClip Clip(const std::string& ball, double drop, double roll_deg) {
  testing::SimOptions o;
  o.ball = ball;
  o.drop_m = drop;
  o.roll_deg = roll_deg;
  o.noise_px = 0.2;
  return testing::MakeSimClip(o);
}

TEST(FlightModel, FitRecoversGravityDragAndRollFromExactArcs) {
  const FlightGlobals truth{3000, 3e-4, 1.5 * kDeg};
  std::vector<FlightArcData> arcs(2);
  const FlightArcParams a0{0.3, 100, 300, 0}, a1{1.1, 260, 305, 6};
  arcs[0].held_before_apex = true;
  for (int i = 0; i < 60; ++i) {
    FlightSample s;
    s.t = 0.1 + i / 120.0;
    FlightPosition(truth, a0, true, s.t, &s.x, &s.y);
    arcs[0].samples.push_back(s);
    s.t = 0.8 + i / 120.0;
    FlightPosition(truth, a1, false, s.t, &s.x, &s.y);
    arcs[1].samples.push_back(s);
  }
  const FlightGlobals start{2800, 0, 0};
  const FlightFit f = FitFlight(arcs, start, {}, FlightFitOptions{});
  ASSERT_TRUE(f.ok);
  EXPECT_NEAR(f.globals.gravity_px, 3000, 0.01);
  EXPECT_NEAR(f.globals.drag_per_px, 3e-4, 1e-7);
  EXPECT_NEAR(f.globals.roll_rad, 1.5 * kDeg, 1e-7);
  EXPECT_NEAR(f.arcs[1].u_apex, 260, 1e-4);
  EXPECT_LT(f.rms_px, 1e-4);
}

TEST(Calibrator, ScaleRollAndFloorFromFreeFlightWithDrag) {
  for (const auto& [ball, drop, roll] :
       {std::tuple{"pingpong", 1.6, 2.0}, std::tuple{"airball", 1.0, -2.0},
        std::tuple{"softball", 1.6, 1.0}}) {
    const auto c = Clip(ball, drop, roll);
    Calibrator cal{CalibratorConfig{}};
    const auto r = cal.Calibrate(ArcsOf(c, 4));
    ASSERT_TRUE(r.ok) << ball << ": " << r.problem;
    const Calibration& k = r.calibration;
    EXPECT_EQ(k.method, "free-fall");
    EXPECT_NEAR(k.px_per_m, c.options.px_per_m, 0.003 * c.options.px_per_m) << ball;
    EXPECT_GT(k.px_per_m_sigma, 0) << ball;
    EXPECT_LT(k.px_per_m_sigma, 0.01 * k.px_per_m) << ball;
    EXPECT_NEAR(k.roll_rad, roll * kDeg, 0.05 * kDeg) << ball;
    // The release height from the calibration: floor minus the release arc's apex.
    const double h = (k.floor_centre_px() - r.flight.arcs[0].u_apex) / k.px_per_m;
    EXPECT_NEAR(h, drop, std::max(0.002, 0.005 * drop)) << ball;
    ASSERT_EQ(r.impacts.size(), 3u);
    for (size_t i = 0; i < r.impacts.size(); ++i)
      EXPECT_NEAR(r.impacts[i].t, c.truth.impact_times_s[i], 1e-3) << ball << " impact " << i;
  }
}

// A hand that pushes the ball down as it lets go (0.6 m/s on a 1 m drop): fitted from rest, the
// fall reads gravity high and every height low. With a rebound to pin gravity, the release
// speed is fitted too; a drop from rest keeps its from-rest fit (the test above).
TEST(Calibrator, APushedReleaseIsFittedWithItsSpeed) {
  for (const char* ball : {"tennis", "pingpong", "basketball"}) {
    testing::SimOptions o;
    o.ball = ball;
    o.noise_px = 0.2;
    o.launch_up_mps = -0.6;
    const auto c = testing::MakeSimClip(o);
    // As the detector has it at the first rebound's apex: the fall, and the rebound's rise.
    CalibrationInput in = ArcsOf(c, 2);
    in.arcs[1].samples.resize(in.arcs[1].samples.size() / 2);
    CalibratorConfig from_rest;
    from_rest.fit_release_speed = false;
    const auto rest = Calibrator{from_rest}.Calibrate(in);
    const auto r = Calibrator{CalibratorConfig{}}.Calibrate(in);
    ASSERT_TRUE(r.ok && rest.ok) << ball;
    const Calibration& k = r.calibration;
    std::printf("%s: scale %.1f px/m (from rest %.1f; truth %.1f), release lead %.4f s\n", ball,
                k.px_per_m, rest.calibration.px_per_m, o.px_per_m, r.flight.arcs[0].lead_s);
    EXPECT_GT(std::abs(rest.calibration.px_per_m / o.px_per_m - 1), 0.03)
        << ball << ": from rest fits it";
    EXPECT_NEAR(k.px_per_m, o.px_per_m, 0.005 * o.px_per_m) << ball;
    const FlightGlobals& g = r.flight.globals;
    const double speed =
        FlightVelocityDown(g.gravity_px, g.drag_per_px, r.flight.arcs[0].lead_s) / k.px_per_m;
    EXPECT_NEAR(speed, 0.6, 0.06) << ball;
    // The release row is the hand, the highest point of the flight.
    const double h = (k.floor_centre_px() - FlightTopU(g, r.flight.arcs[0], true)) / k.px_per_m;
    EXPECT_NEAR(h, o.drop_m, 0.005 * o.drop_m) << ball;
  }
}

// A drop that ends rolling: the detector closes its last "arc" on a ball that rolls along the
// floor (flat, 6 samples). It measures no fall and must not pull the scale down.
TEST(Calibrator, ARollAtTheEndOfADropIsNotAFreeFall) {
  testing::SimOptions o;  // a phone's 24 fps: a few samples an arc, and a roll of as many
  o.ball = "tennis";
  o.fps = 24;
  o.noise_px = 0.2;
  const auto c = testing::MakeSimClip(o);
  CalibrationInput in = ArcsOf(c, 4);
  FlightArcData roll;
  const auto& last = in.arcs.back().samples.back();
  for (int i = 1; i <= 6; ++i) roll.samples.push_back({last.t + 0.2 + i / 24.0, last.x + 8.0 * i, last.y + 3});
  in.arcs.push_back(roll);
  Calibrator cal{CalibratorConfig{}};
  const auto r = cal.Calibrate(in);
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_NEAR(r.calibration.px_per_m, c.options.px_per_m, 0.003 * c.options.px_per_m);
}

TEST(Calibrator, IgnoringDragBiasesTheScaleOfALightBall) {
  // Why drag is modelled: a ping-pong ball falling 1.6 m is far from a parabola.
  const auto c = Clip("pingpong", 1.6, 0);
  CalibratorConfig no_drag;
  no_drag.fit_drag = false;
  const auto biased = Calibrator{no_drag}.Calibrate(ArcsOf(c, 1));
  const auto good = Calibrator{CalibratorConfig{}}.Calibrate(ArcsOf(c, 1));
  ASSERT_TRUE(biased.flight.ok && good.flight.ok);
  const double truth = c.options.px_per_m;
  EXPECT_GT(std::abs(biased.calibration.free_fall_px_per_m / truth - 1), 0.03);
  EXPECT_LT(std::abs(good.calibration.free_fall_px_per_m / truth - 1), 0.01);
}

TEST(Calibrator, UserScaleDropHeightAndDiameterCrossCheck) {
  const auto c = Clip("wiffle", 1.2, 1.0);
  const auto in = ArcsOf(c, 3);

  CalibratorConfig user;
  user.px_per_m = 250;
  const auto ru = Calibrator{user}.Calibrate(in);
  EXPECT_EQ(ru.calibration.method, "user");
  EXPECT_DOUBLE_EQ(ru.calibration.px_per_m, 250);
  EXPECT_NEAR(ru.calibration.free_fall_px_per_m, c.options.px_per_m, 0.003 * c.options.px_per_m);

  CalibratorConfig drop;
  drop.drop_height_m = 1.2;
  const auto rd = Calibrator{drop}.Calibrate(in);
  ASSERT_TRUE(rd.ok) << rd.problem;
  EXPECT_EQ(rd.calibration.method, "drop-height");
  EXPECT_NEAR(rd.calibration.px_per_m, c.options.px_per_m, 0.005 * c.options.px_per_m);

  CalibratorConfig diam;
  diam.ball_diameter_m = 0.072;
  const auto rc = Calibrator{diam}.Calibrate(in);
  EXPECT_NEAR(rc.calibration.diameter_ratio, 1.0, 0.01);
  diam.ball_diameter_m = 0.10;  // the wrong ball: the cross-check says so
  EXPECT_LT(Calibrator{diam}.Calibrate(in).calibration.diameter_ratio, 0.8);
}

// Hops at 24 fps, each a few samples, measured 45 px off (a 180 px ball smeared by its
// motion, or a lock that is partly on something else): the free fall's scale is then known
// to no better than a factor, and the ball's given size is the scale. The same hops measured
// to 0.2 px keep the free fall.
TEST(Calibrator, AFreeFallThatMeasuresNothingGivesWayToTheBallSize) {
  testing::SimOptions o;
  o.ball = "pingpong";
  o.drop_m = 0.08;
  o.fps = 24;
  o.px_per_m = 3400;
  o.floor_y = 1300, o.height = 1400, o.x0 = 380, o.width = 760;
  CalibratorConfig config;
  config.ball_diameter_m = 0.04;
  o.noise_px = 0.2;
  const auto clean = Calibrator{config}.Calibrate(ArcsOf(testing::MakeSimClip(o), 3));
  o.noise_px = 45;
  const auto c = testing::MakeSimClip(o);
  const auto noisy = Calibrator{config}.Calibrate(ArcsOf(c, 3));
  std::printf("free fall %.0f +- %.0f px/m measured to 0.2 px, %.0f +- %.0f to 45 px; used: %s %.0f px/m (truth %.0f)\n",
              clean.calibration.free_fall_px_per_m, clean.calibration.free_fall_sigma,
              noisy.calibration.free_fall_px_per_m, noisy.calibration.free_fall_sigma,
              noisy.calibration.method.c_str(), noisy.calibration.px_per_m, o.px_per_m);
  ASSERT_TRUE(clean.ok && noisy.ok) << clean.problem << noisy.problem;
  EXPECT_EQ(clean.calibration.method, "free-fall");
  EXPECT_NEAR(clean.calibration.px_per_m, o.px_per_m, 0.03 * o.px_per_m);
  EXPECT_GT(noisy.calibration.free_fall_sigma, config.max_free_fall_rel_sigma * noisy.calibration.free_fall_px_per_m);
  EXPECT_EQ(noisy.calibration.method, "ball-diameter");
  EXPECT_NEAR(noisy.calibration.px_per_m, 2 * c.radius_px / 0.04, 1e-9);
  EXPECT_NEAR(noisy.calibration.px_per_m, o.px_per_m, 0.05 * o.px_per_m);
}

TEST(Calibrator, TooLittleFlightIsNotACalibration) {
  CalibrationInput in;
  in.arcs.resize(1);
  in.arcs[0].samples = {{0, 10, 10}, {0.01, 10, 10.5}};
  const auto r = Calibrator{CalibratorConfig{}}.Calibrate(in);
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.problem.empty());
  CalibratorConfig bad;
  bad.px_per_m = 100;
  bad.drop_height_m = 1;
  EXPECT_THROW(Calibrator{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace bouncefit
