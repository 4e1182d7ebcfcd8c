// How a drop starts, on rendered drops: a release from a hold, a release at the first frame
// (no hold seen), and a clip begun mid-bounce (an arc entered in flight, its apex bounce 1).
#include <gtest/gtest.h>

#include <optional>

#include "detect/drop_start.h"
#include "detect_sim.h"

namespace bouncefit {
namespace {

struct Start {
  std::optional<DropStartFound> found;
  double t = 0;  // stream time of the sample that started it
};

// The first start DropStart finds in the clip.
Start FirstStart(const testing::SimClip& clip) {
  DetectorScene scene(SceneConfig{}, CalibratorConfig{});
  DropStart start(DropStartConfig{}, scene);
  for (const auto& o : clip.obs) {
    double t = 0;
    if (!scene.Advance(o.utime, &t) || !o.found) continue;
    const DetectorSample s{t, o.cx, o.cy, o.radius_px, o.utime};
    scene.Saw(s);
    if (auto found = start.OnWaiting(s)) return {found, t};
  }
  return {};
}

TEST(DropStart, AReleaseFromAHoldStartsAHeldArcAFewFramesAfterIt) {
  testing::SimOptions o;
  o.hold_s = 0.3;
  const Start s = FirstStart(testing::MakeSimClip(o));
  ASSERT_TRUE(s.found);
  EXPECT_TRUE(s.found->arc.held);
  EXPECT_FALSE(s.found->arc.entered);
  EXPECT_EQ(s.found->first_bounce, 0);
  EXPECT_GT(s.found->arc.hold_samples, 10u);  // the hold's last 0.25 s
  EXPECT_GT(s.t, o.hold_s);
  EXPECT_LT(s.t, o.hold_s + 8 / o.fps);
}

TEST(DropStart, AReleaseAtTheFirstFrameIsAFallFromAnUnseenHold) {
  testing::SimOptions o;
  o.hold_s = 0;
  const Start s = FirstStart(testing::MakeSimClip(o));
  ASSERT_TRUE(s.found);
  EXPECT_FALSE(s.found->arc.held);
  EXPECT_FALSE(s.found->arc.entered);
  EXPECT_EQ(s.found->first_bounce, 0);
  EXPECT_LT(s.t, 0.1);
}

TEST(DropStart, AClipBegunMidBounceStartsAnEnteredArcWhoseApexIsBounce1) {
  testing::SimOptions o;
  // After the first impact (0.45 s after a 1 m release), rising.
  o.begin_after_release_s = 0.55;
  const auto clip = testing::MakeSimClip(o);
  const Start s = FirstStart(clip);
  ASSERT_TRUE(s.found);
  EXPECT_TRUE(s.found->arc.entered);
  EXPECT_FALSE(s.found->arc.held);
  EXPECT_EQ(s.found->first_bounce, 1);
  // The lock waits for the fall from the arc's vertex (0.27 s: a hand's lift slows into a hold
  // as a rise into its vertex), then reaches back along the arc to the clip's first frames.
  EXPECT_GT(s.t, 0.27);
  EXPECT_LT(s.t, 0.35);
  EXPECT_LT(s.found->arc.samples.front().t, 0.05);
}

// A tennis ball dropped from above the picture at 30 fps crosses it in four frames (no arc
// yet), and its rebound rises out of the picture's top and falls back in: the rise and the fall
// are one arc, entered from an impact (its apex bounce 1), not a fall from a hold above the
// picture that the tracker missed.
TEST(DropStart, ARiseOutOfThePicturesTopAndTheFallBackInAreOneArc) {
  testing::SimOptions o;
  o.ball = "tennis";
  o.drop_m = 1.2;
  o.fps = 30;
  o.px_per_m = 700;
  o.floor_y = 420;
  testing::SimClip clip = testing::MakeSimClip(o);
  for (auto& b : clip.obs) b.found = b.found && b.cy > 0;  // above the top: unseen, or its centre unknown
  const Start s = FirstStart(clip);
  ASSERT_TRUE(s.found);
  const double apex = clip.truth.apex_times_s[1];
  EXPECT_TRUE(s.found->arc.entered);
  EXPECT_EQ(s.found->first_bounce, 1);
  EXPECT_GT(s.t, apex);                                      // once the fall is seen
  EXPECT_LT(s.found->arc.samples.front().t, apex - 0.25);    // its rise the arc's
}

TEST(DropStart, ABallAtRestMovedAgainBringsBackTheWaiting) {
  const auto clip = testing::MakeSimClip({});
  DetectorScene scene(SceneConfig{}, CalibratorConfig{});
  DropStart start(DropStartConfig{}, scene);
  // The clip's last detections: the ball at rest on the floor.
  const auto& rest = clip.obs.back();
  int64_t utime = rest.utime;
  auto sample = [&](double dy) {
    utime += 8333;
    double t = 0;
    scene.Advance(utime, &t);
    return DetectorSample{t, rest.cx, rest.cy + dy, rest.radius_px, utime};
  };
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(start.PickedUp(sample(0)));
  EXPECT_FALSE(start.PickedUp(sample(-20)));
  EXPECT_FALSE(start.PickedUp(sample(-40)));
  EXPECT_TRUE(start.PickedUp(sample(-60)));  // three moves: picked up
}

}  // namespace
}  // namespace bouncefit
