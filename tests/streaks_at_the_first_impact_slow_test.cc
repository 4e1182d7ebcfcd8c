// Streaks at the first impact of a 30 fps clip: a ping-pong ball 14 px across on a pale wall,
// a 1/60 s shutter, a sound track, dropped from 1 m and 1.25 m (4.4 and 4.9 m/s at the first
// impact: streaks of 25-30 px, the ball's colour on no pixel). The fastest frames are the ones
// the first rebound's apex needs: every frame in flight is found at the ball, every apex of
// 2 cm or more within max(2 mm, 2%), none invented, the scale within 2%.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "synth/synth_clip.h"
#include "tests/synth_run_score.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;

class StreaksAtTheFirstImpact : public ::testing::TestWithParam<double> {};

TEST_P(StreaksAtTheFirstImpact, EveryFrameInFlightAndEveryApex) {
  const double drop_m = GetParam();
  const fs::path dir = testing::ScratchDir("streaks_" + std::to_string(static_cast<int>(drop_m * 100)));
  SynthClipConfig c;
  c.drop_height_m = drop_m;
  c.px_per_m = 350;  // the ping-pong ball 14 px across
  c.fps = 30, c.exposure_s = 1.0 / 60;
  c.duration_s = 4;
  c.sound = SynthAudioConfig{};
  c.out = dir / "clip.avi";
  const SynthClipResult clip = RenderSynthClip(c);
  const fs::path out = dir / "run";
  std::string log;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + clip.clip_path.string() +
                                    "' --ball pingpong --no-fit --speed 0 --lcm-url memq:// -q --out '" +
                                    out.string() + "'",
                                &log),
            0)
      << log;
  const std::string name = "drop " + std::to_string(drop_m) + " m";
  testing::ExpectEveryApex(name.c_str(), testing::ScoreSynthRun(clip.truth, out), 5);
  const testing::FlightFrames f = testing::ScoreFramesInFlight(clip.truth, out);
  std::printf("%s: %d frames in flight, %d without the ball where it was:%s\n", name.c_str(), f.in_flight,
              f.without_ball, f.which.c_str());
  EXPECT_GT(f.in_flight, 90);
  EXPECT_EQ(f.without_ball, 0) << f.which;
}

INSTANTIATE_TEST_SUITE_P(ThirtyFps, StreaksAtTheFirstImpact, ::testing::Values(1.0, 1.25));

}  // namespace
}  // namespace bouncefit
