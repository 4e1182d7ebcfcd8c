// A ball tossed sideways at 1.5 m/s, rendered with known truth at 26 fps with a 1/60 s shutter
// over a pebble floor, then `bouncefit run` with nothing but the ball: tossed in from the
// picture's edge, and tossed by a hand whose arm reaches in from the edge (it rises and slows
// after the release as the ball does, and the finder sees it move first). Every apex of 2 cm
// or more within max(2 mm, 2%), none invented, the scale within 2%, and the ball (not the arm)
// in every frame of its flight.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>

#include "synth/synth_clip.h"
#include "tests/synth_run_score.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;

struct Toss {
  const char* name;
  bool hand;
  double ball_x;  // where the toss starts, fraction of the width
};

void PrintTo(const Toss& c, std::ostream* os) { *os << c.name; }

class TossedSideways : public ::testing::TestWithParam<Toss> {};

TEST_P(TossedSideways, EveryApexAndEveryFrameInFlight) {
  const Toss& k = GetParam();
  const fs::path dir = testing::ScratchDir(std::string("tossed_") + k.name);
  SynthClipConfig c;
  c.ball = *FindBallPreset("tennis");
  c.ball_bgr = Bgr{200, 120, 40};  // a blue ball
  c.hand = k.hand;
  c.launch_right_mps = -1.5;
  c.launch_up_mps = 1.0;
  c.ball_x = k.ball_x;
  c.drop_height_m = 0.4;
  c.width = 1280, c.height = 720, c.px_per_m = 450;
  c.fps = 26, c.exposure_s = 0.016;
  c.floor_pattern = FloorPattern::kPebble;
  c.duration_s = 2.2;
  c.out = dir / "clip.avi";
  const SynthClipResult clip = RenderSynthClip(c);
  const SynthTruth& truth = clip.truth;

  const fs::path out = dir / "run";
  std::string log;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + clip.clip_path.string() +
                                    "' --ball tennis --no-fit --no-audio --speed 0 --lcm-url memq:// -q --out '" +
                                    out.string() + "'",
                                &log),
            0)
      << log;
  testing::ExpectEveryApex(k.name, testing::ScoreSynthRun(truth, out), 4);

  // The ball in every frame of its flight: found within a radius of the truth's centre, not
  // on the arm.
  const testing::FlightFrames f = testing::ScoreFramesInFlight(truth, out);
  std::printf("%s: %d frames in flight, %d without the ball where it was:%s\n", k.name, f.in_flight,
              f.without_ball, f.which.c_str());
  EXPECT_GT(f.in_flight, 30);
  EXPECT_EQ(f.without_ball, 0) << f.which;
}

INSTANTIATE_TEST_SUITE_P(AtOneAndAHalfMetresASecond, TossedSideways,
                         ::testing::Values(Toss{"from_the_edge", false, 0.97}, Toss{"from_a_hand", true, 0.8}),
                         [](const ::testing::TestParamInfo<Toss>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace bouncefit
