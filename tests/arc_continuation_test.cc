// Samples an arc of a rendered drop turned away (tests/detector_parts.h), judged for whether
// they are still its flight: a long arc's next samples under a gravity a little off, not a
// straight carry nor one bent far from the drop's gravity; a young fall's next samples, not
// a hand's drift; a young rebound's, not another arc's after an impact it missed.
#include <gtest/gtest.h>

#include <vector>

#include "detect/arc_continuation.h"
#include "detect_sim.h"
#include "detector_parts.h"

namespace bouncefit {
namespace {

using testing::StoppedDrop;

// The clip's next n samples after the current arc's last.
std::vector<DetectorSample> Next(const StoppedDrop& drop, size_t n) {
  return drop.After(drop.arcs.arcs().back().samples.back().t, n);
}

TEST(ArcContinuation, ALongArcContinuesUnderAGravityAQuarterOff) {
  StoppedDrop drop;  // ping-pong, 1 m, 120 fps, 300 px/m
  drop.Stop(drop.clip.truth.apex_times_s[2]);  // the second rebound at its apex
  const ArcContinuation continuation(drop.host.scene, drop.arcs);
  const DetectorArc& cur = drop.arcs.arcs().back();
  ASSERT_TRUE(cur.fit_ok);
  ASSERT_GE(cur.samples.size(), 8u);
  const auto next = Next(drop, 6);
  EXPECT_TRUE(continuation.ArcContinues(cur, next));
  // The drop's gravity fitted 15% off (mostly to another arc): the arc still continues.
  double& g = drop.host.scene.calibration().flight.globals.gravity_px;
  const double g_true = g;
  g = 1.15 * g_true;
  EXPECT_TRUE(continuation.ArcContinues(cur, next));
  // 40% off: not the drop's free flight.
  g = 1.4 * g_true;
  EXPECT_FALSE(continuation.ArcContinues(cur, next));
  g = g_true;
  // A carry on at the last speed in a straight line, no parabola with the arc.
  std::vector<DetectorSample> carried = next;
  for (size_t i = 0; i < carried.size(); ++i) carried[i].y = cur.samples.back().y + 4.0 * static_cast<double>(i + 1);
  EXPECT_FALSE(continuation.ArcContinues(cur, carried));
  // Samples before the arc's last are no continuation.
  EXPECT_FALSE(continuation.ArcContinues(cur, {cur.samples[cur.samples.size() - 2]}));
}

TEST(ArcContinuation, AYoungFallContinuesFasterAndFaster) {
  StoppedDrop drop;
  drop.Stop(drop.clip.truth.release_time_s + 15 * drop.frame());
  ASSERT_FALSE(drop.host.scene.calibrated());
  const ArcContinuation continuation(drop.host.scene, drop.arcs);
  const DetectorArc& fall = drop.arcs.arcs().back();
  ASSERT_TRUE(fall.release);
  const auto next = Next(drop, 6);
  Eigen::Vector3d parabola;
  ASSERT_TRUE(continuation.YoungFallContinues(fall, next, &parabola));
  const double g_px = 9.81 * drop.clip.options.px_per_m;
  EXPECT_NEAR(2 * parabola(2), g_px, 0.15 * g_px);
  // A hand's drift down, a pixel a frame: no free fall for the ball's size.
  std::vector<DetectorSample> drift = next;
  for (size_t i = 0; i < drift.size(); ++i) drift[i].y = fall.samples.back().y + static_cast<double>(i + 1);
  EXPECT_FALSE(continuation.YoungFallContinues(fall, drift, &parabola));
  // Rising is no fall.
  std::vector<DetectorSample> up = next;
  for (size_t i = 0; i < up.size(); ++i) up[i].y = fall.samples.back().y - static_cast<double>(i + 1);
  EXPECT_FALSE(continuation.YoungFallContinues(fall, up, &parabola));
}

TEST(ArcContinuation, AYoungReboundTakesItsNextSamplesNotAnotherArcs) {
  StoppedDrop drop;
  const auto& impacts = drop.clip.truth.impact_times_s;
  drop.Stop(impacts[1] + 6 * drop.frame());  // the second rebound begun
  ASSERT_EQ(drop.arcs.arcs().size(), 3u);
  const ArcContinuation continuation(drop.host.scene, drop.arcs);
  const auto after = drop.After(impacts[1] + 0.5 * drop.frame(), 5);
  // Its first two samples, the first smeared rising from the floor, 25 px off.
  DetectorArc young;
  young.samples = {after[0], after[1]};
  young.samples[0].y -= 25;
  drop.arcs.Refit(young);
  DetectorArc rebound;
  ASSERT_TRUE(continuation.YoungReboundContinues(young, {after[2], after[3], after[4]}, &rebound));
  EXPECT_EQ(rebound.samples.back().t, after[4].t);
  EXPECT_NE(rebound.samples.front().y, young.samples.front().y);  // the smeared one is gone
  EXPECT_TRUE(rebound.fit_ok);
  // The samples of the arc after the next impact left the floor long after this one began.
  const auto later = drop.After(impacts[2] + 2 * drop.frame(), 3);
  EXPECT_FALSE(continuation.YoungReboundContinues(young, later, &rebound));
}

}  // namespace
}  // namespace bouncefit
