// RecordedDrop on a point-mass drop with known truth: the start chosen among the apexes seen,
// the heights and flights after it, flights on another clock dropped, the first fall, the
// heights' uncertainty, a kept drop and its restitution.
#include <gtest/gtest.h>

#include <cmath>

#include "fit/recorded_drop.h"
#include "model/ball_preset.h"
#include "tests/point_mass_truth.h"

namespace bouncefit {
namespace {

// Apex b of the truth drop as the detector reports it: its height, the impact before its
// arc and its time, on the truth's clock scaled by `clock`.
RecordedDrop::Apex TruthApex(const PointMassDropResult& t, int b, double sigma = 0.001, double clock = 1) {
  RecordedDrop::Apex a;
  a.height_m = t.apex_heights_m[b];
  a.sigma_m = sigma;
  a.impact_before_s = b > 0 ? clock * t.impact_times_s[b - 1] : std::nan("");
  a.apex_s = clock * t.apex_times_s[b];
  return a;
}

TEST(RecordedDrop, TheReleaseStartsTheDropAndTheFlightsAreTheTruths) {
  BallPreset ball = *FindBallPreset("tennis");
  ball.restitution = 0.8;
  const PointMassDropResult t = testing::PointMassTruth(ball, 1.2);
  ASSERT_GE(t.apex_heights_m.size(), 6u);
  RecordedDrop d(0.01, 0.002);
  d.Add(1, TruthApex(t, 1));
  d.Add(2, TruthApex(t, 2));
  EXPECT_EQ(d.start_bounce(), 1);  // no release yet: the first apex in view
  EXPECT_DOUBLE_EQ(d.drop_height_m(), t.apex_heights_m[1]);
  d.Add(0, TruthApex(t, 0));  // the release, emitted late
  for (int b = 3; b <= 5; ++b) d.Add(b, TruthApex(t, b));
  ASSERT_TRUE(d.CanFit());
  EXPECT_EQ(d.start_bounce(), 0);
  EXPECT_EQ(d.last_bounce(), 5);
  EXPECT_DOUBLE_EQ(d.drop_height_m(), 1.2);
  ASSERT_EQ(d.fitted_heights().size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(d.fitted_heights()[i], t.apex_heights_m[i + 1]);
  // Arcs 1..4 are timed by the impacts around them; arc 5's impact after it is not seen yet.
  ASSERT_EQ(d.fitted_flights().size(), 5u);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(d.fitted_flights()[i], t.impact_times_s[i + 1] - t.impact_times_s[i], 1e-12) << i;
  EXPECT_TRUE(std::isnan(d.fitted_flights()[4]));
  EXPECT_TRUE(std::isnan(d.flight_clock_ratio()));
  EXPECT_NEAR(d.StartFall(), t.impact_times_s[0] - t.release_time_s, 1e-12);
  EXPECT_NEAR(d.MeasurementSigma(), 0.001, 1e-15);
}

TEST(RecordedDrop, FlightsOnASlowedClockAreDroppedAndMeasured) {
  const BallPreset ball = *FindBallPreset("pingpong");
  const PointMassDropResult t = testing::PointMassTruth(ball, 1.0);
  RecordedDrop d(0.01, 0.002);
  for (int b = 0; b <= 5; ++b) d.Add(b, TruthApex(t, b, 0, 4.0));  // a 4x slow-motion file's stamps
  ASSERT_TRUE(d.CanFit());
  for (double f : d.fitted_flights()) EXPECT_TRUE(std::isnan(f));
  // The flights a height gives ignore drag: a ping-pong ball's are a little shorter.
  EXPECT_NEAR(d.flight_clock_ratio(), 4.0, 0.4);
  // Heights without their own uncertainty: the default.
  EXPECT_DOUBLE_EQ(d.MeasurementSigma(), 0.002);
}

TEST(RecordedDrop, ARunBrokenByAMissedOrHigherApexKeepsTheLongerRun) {
  const BallPreset ball = *FindBallPreset("pingpong");
  const PointMassDropResult t = testing::PointMassTruth(ball, 1.0);
  RecordedDrop d(0.01, 0.002);
  for (int b : {1, 2, 4, 5, 6, 7}) d.Add(b, TruthApex(t, b));  // bounce 3 missed
  EXPECT_EQ(d.start_bounce(), 4);
  EXPECT_EQ(d.fitted_heights().size(), 3u);
  RecordedDrop r(0.01, 0.002);
  for (int b : {0, 1, 2, 3}) r.Add(b, TruthApex(t, b));
  RecordedDrop::Apex again = TruthApex(t, 4);
  again.height_m = 0.9;  // picked up and dropped again: no rebound of bounce 3
  r.Add(4, again);
  EXPECT_EQ(r.start_bounce(), 0);
  EXPECT_EQ(r.fitted_heights().size(), 3u);
  r.Clear();
  EXPECT_FALSE(r.CanFit());
  EXPECT_EQ(r.drop_height_m(), 0);
}

TEST(RecordedDrop, AKeptDropMeasuresTheTruthsRestitution) {
  BallPreset ball = *FindBallPreset("tennis");
  ball.restitution = 0.75;
  ball.restitution_per_mps = 0;
  ball.drag_coefficient = 0;  // no air: each rebound's e is the law's
  const PointMassDropResult t = testing::PointMassTruth(ball, 1.0);
  RecordedDrop d(0.01, 0.002);
  for (int b = 0; b <= 4; ++b) d.Add(b, TruthApex(t, b));
  const KeptDrop kept = d.Keep();
  EXPECT_DOUBLE_EQ(kept.drop_height_m, 1.0);
  EXPECT_EQ(kept.heights_m, d.fitted_heights());
  ASSERT_EQ(kept.sigmas_m.size(), 5u);  // the start's, then the heights'
  const auto points = DropsRestitution({kept, kept}, {{"drag_coefficient", 0.0}}, 0.0, 0.002);
  ASSERT_EQ(points.size(), 8u);
  for (const RestitutionPoint& p : points) EXPECT_NEAR(p.e, 0.75, 1e-3) << p.drop << " " << p.bounce;
  EXPECT_EQ(points.front().drop, 0);
  EXPECT_EQ(points.back().drop, 1);
}

}  // namespace
}  // namespace bouncefit
