// A ball painted with lines of another colour, rendered by `bouncefit synth --seams` with known
// truth at 30 fps and spinning, so that its panels change from frame to frame: a basketball's
// thin channels, a blue rubber ball's orange lines, a tennis ball's winding seam. The lines cut
// the ball's colour into pieces; the ball is still followed whole. `bouncefit run` with nothing
// but the ball finds every apex of 2 cm or more within max(2 mm, 2%) and no false row; the
// tracker (the automatic choice, as `run` has it) finds the ball in every frame in flight, its
// centre within a pixel and its radius within 3% of the truth's (a piece of the ball has
// neither).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>

#include "synth/synth_truth.h"
#include "tests/synth_run_score.h"
#include "tests/test_support.h"
#include "tests/tracker_test_util.h"

namespace bouncefit {
namespace {

struct SeamedClip {
  const char* name;
  const char* ball;
  const char* synth_flags;
};

// ctest's test names show the clip's name, not the parameter's bytes.
void PrintTo(const SeamedClip& c, std::ostream* os) { *os << c.name; }

class SeamedBall : public ::testing::TestWithParam<SeamedClip> {};

TEST_P(SeamedBall, FollowedWholeAndEveryApexFound) {
  const SeamedClip& c = GetParam();
  const auto dir = testing::ScratchDir(c.name);
  const auto clip = dir / "clip.avi", out = dir / "run";
  std::string log;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " synth -q --ball " + c.ball +
                                    " --fps 30 --size 480x864 --spin 0.8 --duration 3.5 " + c.synth_flags + " -o '" +
                                    clip.string() + "'",
                                &log),
            0)
      << log;
  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(clip));
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + clip.string() + "' --ball " + c.ball +
                                    " --no-fit --no-audio --speed 0 --lcm-url memq:// -q --out '" + out.string() + "'",
                                &log),
            0)
      << log;
  testing::ExpectEveryApex(c.name, testing::ScoreSynthRun(truth, out), 4);

  const testing::TrackScore s = testing::TrackClip(clip, TrackerConfig{}, &truth);
  const double rest = truth.comes_to_rest ? truth.rest_t_s : 1e9;
  int in_flight = 0, lost = 0, off_centre = 0, off_size = 0;
  double worst_px = 0, worst_radius = 0;
  std::string which;
  for (size_t i = 0; i < truth.frames.size() && i < s.obs.size(); ++i) {
    const SynthTruthFrame& t = truth.frames[i];
    if (!t.fully_in_view || t.t_s <= truth.release_t_s + 0.01 || t.t_s >= rest) continue;
    ++in_flight;
    const BallObservation& o = s.obs[i];
    if (!o.found) {
      ++lost, which += " " + std::to_string(i) + " lost";
      continue;
    }
    const double e = std::hypot(o.cx - t.cx, o.cy - t.cy), dr = o.radius_px / truth.radius_px - 1;
    worst_px = std::max(worst_px, e), worst_radius = std::max(worst_radius, std::abs(dr));
    if (e > 1.0) ++off_centre, which += " " + std::to_string(i) + " centre " + std::to_string(e) + " px";
    if (std::abs(dr) > 0.03) ++off_size, which += " " + std::to_string(i) + " radius " + std::to_string(dr);
  }
  std::printf("%s: %d frames in flight, %d lost, %d with the centre over 1 px off (worst %.2f px), %d with the radius "
              "over 3%% off (worst %.1f%%)\n%s\n",
              c.name, in_flight, lost, off_centre, worst_px, off_size, 100 * worst_radius, s.describe.c_str());
  EXPECT_GT(in_flight, 40);
  EXPECT_EQ(lost, 0) << which;
  EXPECT_EQ(off_centre, 0) << which;
  EXPECT_EQ(off_size, 0) << which;
}

INSTANTIATE_TEST_SUITE_P(
    Clips, SeamedBall,
    ::testing::Values(
        // The preset's orange with near-black channels 4% of its diameter wide (narrower ones
        // blur into a darker orange, which is the ball's colour still), 160 px across: eight
        // panels and more in view.
        SeamedClip{"basketball_channels", "basketball", "--seams basketball --seam-width 0.04 --drop-height 0.8"},
        // Blue with orange lines a twentieth of its diameter wide, the lines' hue far from the
        // ball's (the shared clip of a blue rubber basketball).
        SeamedClip{"blue_ball_orange_lines", "basketball",
                   "--seams basketball --seam-width 0.05 --color 205,136,82 --seam-color 60,100,225 --drop-height 0.8"},
        // The preset's yellow-green with a white seam a twentieth of its diameter wide, 120 px
        // across.
        SeamedClip{"tennis_seam", "tennis", "--seams tennis --seam-width 0.05 --px-per-m 1800 --drop-height 0.3"}),
    [](const ::testing::TestParamInfo<SeamedClip>& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace bouncefit
