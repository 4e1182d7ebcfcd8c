// The detector's scene: the clock a rendered drop's frames make, the ball's size from its
// detections, and the slow-down a bend at gravity over k^2 says.
#include <gtest/gtest.h>

#include <stdexcept>

#include "detect/detector_scene.h"
#include "detect_sim.h"

namespace bouncefit {
namespace {

// The scene after every detection of a rendered 1 m ping-pong drop at 120 fps, 300 px/m.
DetectorScene SceneOf(const testing::SimClip& clip, SceneConfig config = {}) {
  CalibratorConfig cal;
  cal.ball_diameter_m = 0.040;
  DetectorScene scene(config, cal);
  for (const auto& o : clip.obs) {
    double t = 0;
    if (!scene.Advance(o.utime, &t) || !o.found) continue;
    scene.Saw({t, o.cx, o.cy, o.radius_px, o.utime});
  }
  return scene;
}

TEST(DetectorScene, TheClockIsTheFramesMedianPeriodFromTheFirstFrame) {
  const auto clip = testing::MakeSimClip({});
  DetectorScene scene = SceneOf(clip);
  EXPECT_NEAR(scene.frame_dt(), 1.0 / 120, 1e-6);
  EXPECT_EQ(scene.last_utime(), clip.obs.back().utime);
  EXPECT_EQ(scene.ToUtime(1.0), clip.obs.front().utime + 1'000'000);
  double t = 0;
  EXPECT_FALSE(scene.Advance(clip.obs.back().utime, &t));  // a duplicate frame
  EXPECT_THROW(scene.Advance(clip.obs.front().utime, &t), std::invalid_argument);
}

TEST(DetectorScene, AGivenTimeScaleMakesTheClockRealSeconds) {
  SceneConfig config;
  config.time_scale = 0.25;  // a 4x slow-motion file
  const DetectorScene scene = SceneOf(testing::MakeSimClip({}), config);
  EXPECT_TRUE(scene.clock_decided());
  EXPECT_NEAR(scene.frame_dt(), 0.25 / 120, 1e-7);
}

TEST(DetectorScene, TheBallsSizeGivesGravityInPixelsAndTheClocksABendIsOn) {
  const auto clip = testing::MakeSimClip({});
  const DetectorScene scene = SceneOf(clip);
  EXPECT_NEAR(scene.RadiusPx(), clip.radius_px, 1e-3);
  const double g_px = 9.81 * 300;  // the clip's scale
  EXPECT_NEAR(scene.SizeGravityPx(), g_px, 0.01 * g_px);
  EXPECT_EQ(scene.SlowdownOfBend(g_px), 1);
  // A file slowed 4x or 8x without saying so bends at g / 16 or g / 64; a hand at anything.
  EXPECT_EQ(scene.SlowdownOfBend(g_px / 16), 4);
  EXPECT_EQ(scene.SlowdownOfBend(g_px / 64), 8);
  EXPECT_EQ(scene.SlowdownOfBend(g_px / 100), 0);
}

TEST(DetectorScene, GatesFollowTheNoiseAndTheSpeed) {
  const DetectorScene scene = SceneOf(testing::MakeSimClip({}));
  const SceneConfig config;
  EXPECT_DOUBLE_EQ(scene.Gate(), config.gate_sigmas * config.initial_noise_px);
  EXPECT_NEAR(scene.FollowGate(1200), scene.Gate() + 0.02 * 1200 / 120, 1e-4);
  // Before the noise is measured an arc's first samples get a share of the ball's radius.
  EXPECT_GE(scene.StartGate(), scene.Gate());
  EXPECT_DOUBLE_EQ(scene.MinApexPx(), std::max(config.min_apex_px, 5 * config.initial_noise_px));
}

}  // namespace
}  // namespace bouncefit
