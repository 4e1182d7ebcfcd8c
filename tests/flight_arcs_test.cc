// The drop's arcs of a rendered drop, stopped mid-flight (tests/detector_parts.h): each arc
// foresees the ball where the truth is, under the calibration and before it; a young
// rebound's first sample is dropped when it is off the arc; the first rebound's gate carries
// the scale's uncertainty; the arcs' noise is the clip's.
#include <gtest/gtest.h>

#include <cmath>

#include "detect/flight_arcs.h"
#include "detect_sim.h"
#include "detector_parts.h"

namespace bouncefit {
namespace {

using testing::StoppedDrop;

TEST(FlightArcs, AClosedArcForeseesTheBallWhereTheTruthIs) {
  StoppedDrop drop;  // ping-pong, 1 m, 120 fps, 300 px/m
  const auto& impacts = drop.clip.truth.impact_times_s;
  const auto& o = drop.clip.options;
  drop.Stop(impacts[2] + 0.05);
  ASSERT_TRUE(drop.host.scene.calibrated());
  ASSERT_GE(drop.arcs.arcs().size(), 3u);
  const DetectorArc& rebound = drop.arcs.arcs()[1];
  ASSERT_TRUE(rebound.fit_ok);
  // Between its impacts, a frame clear of each (an exposure there straddles the impact).
  for (double t = impacts[0] + drop.frame(); t < impacts[1] - drop.frame(); t += drop.frame()) {
    double u, w, v;
    ASSERT_TRUE(drop.arcs.Predict(rebound, t, &u, &w, &v));
    EXPECT_NEAR(u, testing::TruthDown(drop.clip, t), 0.5) << "t " << t;
    EXPECT_NEAR(w, o.x0, 0.5) << "t " << t;
    // Down the picture is down: the speed is the truth's, falling positive.
    EXPECT_NEAR(v, -drop.clip.truth.At(t).velocity_mps * o.px_per_m, 0.03 * o.px_per_m) << "t " << t;
  }
  // The impact that began the current arc, where the truth's is.
  const FlightImpact* began = drop.arcs.ImpactBeforeCurrent();
  ASSERT_NE(began, nullptr);
  EXPECT_NEAR(began->t, impacts[drop.arcs.arcs().size() - 2], 0.5 * drop.frame());
}

TEST(FlightArcs, BeforeAScaleTheFirstFallIsALocalCurve) {
  // A few frames below the hand (a curve in the square root of the drop), then a dozen (a
  // quadratic through the last samples): the next frame foreseen within a pixel or two.
  for (int frames : {5, 16}) {
    StoppedDrop drop;
    drop.Stop(drop.clip.truth.release_time_s + frames * drop.frame());
    ASSERT_FALSE(drop.host.scene.calibrated());
    ASSERT_EQ(drop.arcs.arcs().size(), 1u);
    const DetectorArc& fall = drop.arcs.arcs()[0];
    const double next = fall.samples.back().t + drop.frame();
    double u, w, v;
    ASSERT_TRUE(drop.arcs.Predict(fall, next, &u, &w, &v)) << frames << " frames";
    EXPECT_NEAR(u, testing::TruthDown(drop.clip, next), 2.0) << frames << " frames";
    EXPECT_NEAR(w, drop.clip.options.x0, 1.0) << frames << " frames";
    EXPECT_GT(v, 0) << frames << " frames";
  }
}

TEST(FlightArcs, AYoungReboundDropsAFirstSampleOffItsArc) {
  StoppedDrop drop;
  const double impact = drop.clip.truth.impact_times_s[1];
  drop.Stop(impact + 0.05);
  ASSERT_TRUE(drop.host.scene.calibrated());
  ASSERT_EQ(drop.arcs.arcs().size(), 3u);
  const double gate = drop.host.scene.Gate();
  const double late_limit = drop.config.off_arc_radius_share * drop.host.scene.RadiusPx();
  ASSERT_LT(gate, late_limit);
  // The rebound's first four samples, from `after` the impact on; the first moved up by `off`.
  auto young = [&](double after, double off) {
    DetectorArc a;
    a.samples = drop.After(impact + after, 4);
    a.samples.front().y -= off;
    drop.arcs.Refit(a);
    return a;
  };
  // Within a frame or two of the impact it may straddle it: off by more than the gate, it goes.
  EXPECT_EQ(young(0.5 * drop.frame(), 0).samples.size(), 4u);
  DetectorArc straddling = young(0.5 * drop.frame(), 3 * gate);
  EXPECT_EQ(straddling.samples.size(), 3u);
  EXPECT_TRUE(straddling.fit_ok);
  EXPECT_EQ(straddling.late_drops, 0);
  // Later, only when off by a good part of the ball's radius (a smeared streak).
  EXPECT_EQ(young(4 * drop.frame(), 0.5 * (gate + late_limit)).samples.size(), 4u);
  DetectorArc streak = young(4 * drop.frame(), 2 * late_limit);
  EXPECT_EQ(streak.samples.size(), 3u);
  EXPECT_EQ(streak.late_drops, 1);
}

TEST(FlightArcs, TheFirstReboundsGateCarriesTheScalesUncertainty) {
  StoppedDrop drop;
  drop.Stop(drop.clip.truth.impact_times_s[0] + 8 * drop.frame());
  ASSERT_TRUE(drop.host.scene.calibrated());
  ASSERT_EQ(drop.arcs.arcs().size(), 2u);
  const DetectorArc& rebound = drop.arcs.arcs()[1];
  ASSERT_GE(rebound.samples.size(), 4u);
  const double v = 300, t_next = rebound.samples.back().t + drop.frame();
  const double t_later = t_next + 20 * drop.frame();
  // Farther from its samples in time, the scale's error moves the arc more.
  const double near = drop.arcs.FollowGate(rebound, t_next, v, 1);
  EXPECT_GT(drop.arcs.FollowGate(rebound, t_later, v, 1), near + 0.5);
  EXPECT_GE(near, drop.host.scene.FollowGate(v));
  // Without it, the gate is the scene's wherever the sample is.
  FlightFollowerConfig no_scale_gate;
  no_scale_gate.scale_gate_sigmas = 0;
  FlightArcs arcs(no_scale_gate, drop.host.scene);
  arcs.arcs() = drop.arcs.arcs();
  EXPECT_DOUBLE_EQ(arcs.FollowGate(rebound, t_later, v, 1), arcs.FollowGate(rebound, t_next, v, 1));
}

TEST(FlightArcs, AnArcsScatterIsTheClipsNoise) {
  for (double noise : {0.15, 0.6}) {
    testing::SimOptions o;
    o.noise_px = noise;
    StoppedDrop drop(o);
    drop.Stop(drop.clip.truth.impact_times_s[2]);
    ASSERT_TRUE(drop.host.scene.calibrated());
    ASSERT_GE(drop.arcs.arcs().size(), 2u);
    const double scatter = drop.arcs.Scatter(drop.arcs.arcs()[1]);
    EXPECT_GT(scatter, 0.6 * noise) << noise << " px";
    EXPECT_LT(scatter, 1.6 * noise) << noise << " px";
  }
}

TEST(FlightArcs, TheCalibratorTakesTheArcsSamplesAndTimesRescale) {
  StoppedDrop drop;
  drop.Stop(drop.clip.truth.impact_times_s[1]);
  FlightArcs& arcs = drop.arcs;
  const auto data = arcs.Data();
  ASSERT_EQ(data.size(), arcs.arcs().size());
  for (size_t j = 0; j < data.size(); ++j) {
    ASSERT_EQ(data[j].samples.size(), arcs.arcs()[j].samples.size());
    EXPECT_EQ(data[j].held_before_apex, arcs.arcs()[j].held);
    EXPECT_EQ(data[j].samples.back().t, arcs.arcs()[j].samples.back().t);
  }
  const DetectorArc before = arcs.arcs()[1];
  arcs.RescaleTime(2);
  const DetectorArc& after = arcs.arcs()[1];
  EXPECT_EQ(after.samples.back().t, 2 * before.samples.back().t);
  EXPECT_EQ(after.fit.t_apex, 2 * before.fit.t_apex);
  EXPECT_FALSE(after.fit_ok);  // fitted in the old time
}

}  // namespace
}  // namespace bouncefit
