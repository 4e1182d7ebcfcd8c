// Several drops in one rendered clip (synth/synth_drops.h): each drop's truth is its own
// pinhole scale, floor line and release, the frames put the ball where that truth says, and
// the truth file reads back as written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "model/ball_preset.h"
#include "synth/synth_drops.h"
#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

SynthClipConfig TwoDrops(const std::filesystem::path& out) {
  SynthClipConfig c;
  c.ball = *FindBallPreset("softball");  // comes to rest soon (e 0.42)
  c.drop_distances_m = {1.2, 2.0};
  c.drop_heights_m = {0.5, 0.4};
  c.hold_s = 0.2;
  c.roll_s = 0.4;
  c.lift_s = 0.3;
  c.width = 180;
  c.height = 320;
  c.fps = 30;
  c.noise_sigma = 0;
  c.exposure_s = 0;
  c.out = out;
  return c;
}

TEST(SynthDrops, EachDropHasItsOwnScaleFloorAndRelease) {
  const auto dir = testing::ScratchDir("synth_two_drops");
  const SynthClipConfig c = TwoDrops(dir / "two.avi");
  const SynthClipResult r = RenderSynthClip(c);
  const SynthTruth& t = r.truth;
  ASSERT_EQ(t.drops.size(), 2u);
  const SynthPinhole cam = FitSynthPinhole(c);
  EXPECT_NEAR(t.camera_focal_px, cam.focal_px, 1e-9);
  for (size_t k = 0; k < 2; ++k) {
    const SynthTruthDrop& d = t.drops[k];
    EXPECT_NEAR(d.px_per_m, cam.focal_px / c.drop_distances_m[k], 1e-9);
    EXPECT_NEAR(d.radius_px, c.ball.radius_m() * d.px_per_m, 1e-9);
    EXPECT_DOUBLE_EQ(d.apex_heights_m.front(), c.drop_heights_m[k]);
    EXPECT_DOUBLE_EQ(d.apex_times_s.front(), d.release_t_s);
    // Held still before its release: the ball's centre a radius and the drop height above
    // its own floor line, at its own scale.
    const auto held = std::find_if(t.frames.begin(), t.frames.end(),
                                   [&](const SynthTruthFrame& f) { return f.t_s > d.release_t_s - 0.1; });
    ASSERT_NE(held, t.frames.end());
    const double above = d.floor_offset_px - (held->cx * t.down_x + held->cy * t.down_y);
    EXPECT_NEAR(above, d.radius_px + d.drop_height_m * d.px_per_m, 1e-6) << "drop " << k;
    EXPECT_NEAR(held->height_m, d.drop_height_m, 1e-9);
  }
  // The second drop, farther: smaller, its floor line higher in the picture, released after
  // the first rested, rolled, was lifted and held.
  EXPECT_LT(t.drops[1].px_per_m, t.drops[0].px_per_m);
  EXPECT_LT(t.drops[1].floor_offset_px, t.drops[0].floor_offset_px);
  EXPECT_NEAR(t.drops[1].release_t_s, t.drops[0].rest_t_s + 0.3 + c.roll_s + 0.3 + c.lift_s + c.hold_s, 1e-9);
  EXPECT_EQ(t.apex_times_s.size(), t.drops[0].apex_times_s.size() + t.drops[1].apex_times_s.size());
  // Every frame in the picture, and the clip as long as the truth says.
  EXPECT_TRUE(std::all_of(t.frames.begin(), t.frames.end(), [](const SynthTruthFrame& f) { return f.fully_in_view; }));
  EXPECT_EQ(static_cast<int>(t.frames.size()), t.frame_count);

  const SynthTruth back = LoadSynthTruth(r.truth_path);
  ASSERT_EQ(back.drops.size(), 2u);
  EXPECT_NEAR(back.drops[1].px_per_m, t.drops[1].px_per_m, 1e-6);
  EXPECT_EQ(back.drops[1].apex_heights_m.size(), t.drops[1].apex_heights_m.size());
  EXPECT_NEAR(back.camera_height_m, cam.height_m, 1e-9);
}

// A camera looking down, raised to look at the drop: the held ball and the ball at rest (come
// closer as it bounced) are where the pitched pinhole puts them, every frame in the picture.
TEST(SynthDrops, ACameraLookingDownSeesTheBallWhereItsPinholeSays) {
  const auto dir = testing::ScratchDir("synth_drops_pitched");
  SynthClipConfig c = TwoDrops(dir / "pitched.avi");
  c.drop_distances_m = {1.5};
  c.drop_heights_m = {0.5};
  c.camera_pitch_deg = 30;
  c.approach_mps = 0.1;
  const SynthClipResult r = RenderSynthClip(c);
  const SynthTruth& t = r.truth;
  const SynthPinhole cam = FitSynthPinhole(c);
  const double radius = c.ball.radius_m();
  EXPECT_NEAR(cam.pitch_rad, 30 * M_PI / 180, 1e-12);
  // The drop's middle on the axis.
  EXPECT_NEAR(cam.See(0, 0.5 * (0.5 + 2 * radius), 1.5).down, 0, 1e-12);
  EXPECT_TRUE(std::all_of(t.frames.begin(), t.frames.end(), [](const SynthTruthFrame& f) { return f.fully_in_view; }));
  const double cy = (c.height - 1) / 2.0;
  const SynthTruthFrame& held = t.frames.front();
  EXPECT_NEAR(held.cy, cy + cam.focal_px * cam.See(0, 0.5 + radius, 1.5).down, 1e-6);
  const SynthTruthDrop& d = t.drops.front();
  const SynthTruthFrame& rest = t.frames.back();
  ASSERT_GT(rest.t_s, d.rest_t_s);
  const double nearer = 1.5 - c.approach_mps * (d.rest_t_s - d.release_t_s);
  EXPECT_NEAR(rest.cy, cy + cam.focal_px * cam.See(0, radius, nearer).down, 1e-6);
  // Nearer, lower in the picture than where it first met the floor.
  EXPECT_GT(rest.cy, cy + cam.focal_px * cam.See(0, radius, 1.5).down + 5);
}

TEST(SynthDrops, BadConfigsAreOneLineErrors) {
  const auto dir = testing::ScratchDir("synth_drops_bad");
  SynthClipConfig c = TwoDrops(dir / "bad.avi");
  c.drop_heights_m = {0.5};
  EXPECT_THROW(RenderSynthClip(c), std::invalid_argument);
  c = TwoDrops(dir / "bad.avi");
  c.launch_up_mps = 1;
  EXPECT_THROW(RenderSynthClip(c), std::invalid_argument);
  c = TwoDrops(dir / "bad.avi");
  c.approach_mps = 3;  // within 0.2 m of the camera before it rests
  EXPECT_THROW(RenderSynthClip(c), std::invalid_argument);
  c = TwoDrops(dir / "bad.avi");
  c.camera_pitch_deg = 75;
  EXPECT_THROW(RenderSynthClip(c), std::invalid_argument);
}

}  // namespace
}  // namespace bouncefit
