// The tracker on rendered clips with known truth (bouncefit synth): centre accuracy on all four
// presets, distractors, empty scenes, YUYV input.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/test_support.h"
#include "tests/tracker_test_util.h"

namespace bouncefit {
namespace {

using testing::ConfigForColor;
using testing::TrackClip;
using testing::TrackScore;

SynthClipResult Render(const std::string& dir, const std::string& ball, double duration_s,
                       bool distractor = false) {
  SynthClipConfig c;
  c.ball = *FindBallPreset(ball);
  c.noise_sigma = 3;
  c.roll_deg = 1;
  c.hold_s = 0.1;
  c.duration_s = duration_s;
  c.distractor = distractor;
  c.out = testing::ScratchDir(dir) / (ball + ".avi");
  return RenderSynthClip(c);
}

void Print(const std::string& what, const TrackScore& s) {
  std::printf("%-10s in view %d lost %d wrong %d | centre error rms %.3f p99 %.3f max %.3f px, "
              "bias %+.3f,%+.3f\n  %s\n",
              what.c_str(), s.in_view, s.lost, s.wrong, s.rms, s.p99, s.max, s.mean_dx,
              s.mean_dy, s.describe.c_str());
}

class TrackerPreset : public ::testing::TestWithParam<std::string> {};

TEST_P(TrackerPreset, CentreWithinAFewTenthsOfAPixel) {
  const std::string ball = GetParam();
  const SynthClipResult clip = Render("tracker_" + ball, ball, 2.0);
  const TrackScore s = TrackClip(clip.clip_path, ConfigForColor(clip.truth.ball_color_bgr, ball),
                                 &clip.truth);
  Print(ball, s);
  ASSERT_GT(s.in_view, 100);
  EXPECT_EQ(s.lost, 0);
  EXPECT_EQ(s.wrong, 0);
  EXPECT_LE(s.rms, 0.3);
  EXPECT_LE(s.p99, 1.0);
}

INSTANTIATE_TEST_SUITE_P(AllPresets, TrackerPreset,
                         ::testing::Values("pingpong", "wiffle", "softball", "airball"));

}  // namespace
}  // namespace bouncefit
