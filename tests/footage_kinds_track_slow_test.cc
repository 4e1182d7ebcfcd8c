// Kinds of footage the tracker must follow, each rendered by `bouncefit synth` with known truth
// and run as a user runs it (`bouncefit run CLIP --ball B`): a ball streaked by a 1/60 s
// shutter at 30 and 24 fps, a close-up ball a third of the frame tall (before a poster wall
// that shares its hue; cut by the frame's top on a 1080 px square), and a sideways toss at the
// frame's edge over a pebble floor. On each: every apex of 2 cm or more found within
// max(2 mm, 2%), no false one, the scale within 2%; and from the tracker itself (the same
// automatic choice, in this process) the ball found in every frame in flight once it is
// locked, its centre and size unbiased; and found from the release on (the finder sees what
// moves: the frames before it saw the ball are looked at again once it has, as `run` does).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "detect/bounce_detector.h"
#include "synth/synth_truth.h"
#include "tests/test_support.h"
#include "tests/tracker_test_util.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;

struct KindScore {
  int apexes = 0, apexes_within = 0, false_rows = 0;
  double scale = 0;  // calibration's px_per_m over the truth's
  std::string misses;
};

// Renders `synth_flags` into `dir`, runs it, and scores peaks.csv and calibration.json against
// the truth as the must-show does.
KindScore RenderAndRun(const fs::path& dir, const std::string& synth_flags, const std::string& ball,
                       SynthTruth* truth) {
  KindScore k;
  const fs::path clip = dir / "clip.avi", out = dir / "out";
  std::string log;
  EXPECT_EQ(RunCommand(BouncefitExe() + " synth -q --ball " + ball + " " + synth_flags + " --out '" +
                           clip.string() + "'", &log), 0) << log;
  *truth = LoadSynthTruth(SynthTruthPathFor(clip));
  const int rc = RunCommand(BouncefitExe() + " run '" + clip.string() + "' --ball " + ball +
                                " --no-fit --no-audio --speed 0 --lcm-url memq:// --out '" + out.string() + "'",
                            &log);
  EXPECT_EQ(rc, 0) << log;
  const auto rows = testing::ReadCsv(out / "peaks.csv");
  std::vector<bool> used(rows.size(), false);
  const double end = truth->frame_count / truth->fps;
  for (size_t a = 0; a < truth->apex_times_s.size(); ++a) {
    const double t = truth->apex_times_s[a], h = truth->apex_heights_m[a];
    int match = -1;
    for (size_t j = 0; j < rows.size(); ++j)
      if (std::abs(std::stod(rows[j].at("t_s")) - t) < 0.06) match = static_cast<int>(j);
    if (match >= 0) used[static_cast<size_t>(match)] = true;
    // An apex within a frame and a half of the clip's ends may be found or not (no frames on
    // its other side), and so may a hop at the picture's limit (its flight within 5% of the
    // shortest the detector measures: 3.8 frames, 1.97 cm at 30 fps); the rest of 2 cm and more
    // must be.
    const double flight_frames = 2 * std::sqrt(2 * h / 9.81) * truth->fps;
    const bool at_limit = flight_frames < 1.05 * BounceDetectorConfig{}.min_flight_frames;
    if (t < 1.5 / truth->fps || t > end - 1.5 / truth->fps || h < 0.02 || at_limit) continue;
    ++k.apexes;
    const double got = match >= 0 ? std::stod(rows[static_cast<size_t>(match)].at("height_m")) : -1;
    if (match >= 0 && std::abs(got - h) <= std::max(0.002, 0.02 * h))
      ++k.apexes_within;
    else
      k.misses += " apex at " + std::to_string(t) + " s of " + std::to_string(h) + " m: got " + std::to_string(got);
  }
  for (bool u : used) k.false_rows += !u;
  const auto cal = nlohmann::json::parse(std::ifstream(out / "calibration.json"));
  k.scale = cal.value("px_per_m", 0.0) / truth->px_per_m;
  std::printf("%s: %d of %d apexes within max(2 mm, 2%%), %d false, scale %.4f%s\n", synth_flags.c_str(),
              k.apexes_within, k.apexes, k.false_rows, k.scale, k.misses.c_str());
  return k;
}

struct FlightScore {
  int in_flight = 0;      // frames with the ball in view between the release and the rest
  int before_lock = 0;    // ... before the tracker first found it in flight
  int lost = 0;           // ... after that, not found
  double mean_dx = 0, mean_dy = 0, max_err = 0;  // centre against the truth, px
  double radius_ratio = 0;  // mean radius found over the truth's
};

// The tracker (automatic choice, as `run` has it) over the clip: the frames in flight.
FlightScore TrackFlight(const fs::path& clip, const SynthTruth& truth) {
  const testing::TrackScore s = testing::TrackClip(clip, TrackerConfig{}, &truth);
  FlightScore f;
  const double rest = truth.comes_to_rest ? truth.rest_t_s : 1e9;
  bool locked = false;
  int n = 0;
  for (size_t i = 0; i < truth.frames.size() && i < s.obs.size(); ++i) {
    const SynthTruthFrame& t = truth.frames[i];
    if (!t.fully_in_view || t.t_s <= truth.release_t_s + 0.01 || t.t_s >= rest) continue;
    ++f.in_flight;
    const BallObservation& o = s.obs[i];
    locked = locked || o.found;
    if (!locked) {
      ++f.before_lock;
      continue;
    }
    if (!o.found) {
      ++f.lost;
      continue;
    }
    ++n;
    f.mean_dx += o.cx - t.cx, f.mean_dy += o.cy - t.cy;
    f.max_err = std::max(f.max_err, std::hypot(o.cx - t.cx, o.cy - t.cy));
    f.radius_ratio += o.radius_px / truth.radius_px;
  }
  if (n > 0) f.mean_dx /= n, f.mean_dy /= n, f.radius_ratio /= n;
  std::printf("tracker: %d frames in flight, %d before the lock, %d lost after it; centre bias %.2f, %.2f px, "
              "worst %.2f px; radius %.4f of the truth's\n%s\n", f.in_flight, f.before_lock, f.lost, f.mean_dx,
              f.mean_dy, f.max_err, f.radius_ratio, s.describe.c_str());
  return f;
}

void ExpectMustShow(const KindScore& k) {
  EXPECT_GT(k.apexes, 0);
  EXPECT_EQ(k.apexes_within, k.apexes) << k.misses;
  EXPECT_EQ(k.false_rows, 0);
  EXPECT_NEAR(k.scale, 1.0, 0.02);
}

// A ping-pong ball at 30 and 24 fps with a 1/60 s shutter: near each impact it sweeps twice its
// diameter over the exposure, and no pixel holds its colour.
class TrackKindsStreak : public ::testing::TestWithParam<int> {};

TEST_P(TrackKindsStreak, FollowedInEveryFrameInFlightAtItsMidExposureCentre) {
  const int fps = GetParam();
  const fs::path dir = testing::ScratchDir("streak_" + std::to_string(fps));
  SynthTruth truth;
  const KindScore k = RenderAndRun(dir, "--fps " + std::to_string(fps) + " --exposure 0.01667 --duration 4",
                                   "pingpong", &truth);
  ExpectMustShow(k);
  const FlightScore f = TrackFlight(dir / "clip.avi", truth);
  // Found in every frame from the release on: those before the finder saw it move, and one
  // after an impact at 24 fps that the prediction's new arc (of the bottom sample and one
  // after it) sent the window past, are found looking back from the next sighting.
  EXPECT_EQ(f.before_lock, 0);
  EXPECT_EQ(f.lost, 0);
  // The centre: the ball at mid-exposure; the size: not the streak's. (A fast frame's rim at
  // half coverage lies inside the ball across the motion: the mean radius is 6% short.)
  EXPECT_LT(std::abs(f.mean_dx), 0.3);
  EXPECT_LT(std::abs(f.mean_dy), 0.5);
  EXPECT_LT(f.max_err, 3.0);
  EXPECT_LT(f.radius_ratio, 1.02);
  EXPECT_GT(f.radius_ratio, 0.9);
}

INSTANTIATE_TEST_SUITE_P(SixtiethOfASecond, TrackKindsStreak, ::testing::Values(30, 24));

// A close-up held still, then dropped 10-12 cm at 30 fps (a fall of four frames): every apex
// from the release on, no false one, the scale; the ball found in every frame of its flight,
// centred and sized within a pixel and 2%.
void ExpectCloseUpFollowed(const std::string& tag, const std::string& synth_flags) {
  const fs::path dir = testing::ScratchDir(tag);
  SynthTruth truth;
  const KindScore k = RenderAndRun(dir, synth_flags, "tennis", &truth);
  ExpectMustShow(k);
  const FlightScore f = TrackFlight(dir / "clip.avi", truth);
  EXPECT_EQ(f.before_lock, 0);
  EXPECT_EQ(f.lost, 0);
  EXPECT_LT(std::hypot(f.mean_dx, f.mean_dy), 0.5);
  EXPECT_LT(f.max_err, 3.0);
  EXPECT_NEAR(f.radius_ratio, 1.0, 0.02);
}

// A tennis ball 240 px across in a 720 px square, before a poster wall whose patches share its
// hue: its blob runs together with them.
TEST(TrackKindsCloseUp, ThirdOfTheFrameBeforeAPosterAt30Fps) {
  ExpectCloseUpFollowed("close_up_poster", "--fps 30 --size 720x720 --px-per-m 3582 --drop-height 0.1 "
                                           "--duration 2.5 --wall-pattern poster --exposure 0.01");
}

// A third of a 1080 px square, released with its top out of the frame.
TEST(TrackKindsCloseUp, ThirdOfA1080FrameCutByItsTop) {
  ExpectCloseUpFollowed("close_up_1080", "--fps 30 --size 1080x1080 --px-per-m 5373 --drop-height 0.12 "
                                         "--duration 2 --exposure 0.01");
}

// Tossed sideways from the frame's left edge at 26 fps over a floor of pebbles a ball across,
// in greys and browns: one or two rebounds, the clip begun after the toss.
TEST(TrackKindsToss, AtTheEdgeOverAPebbleFloor) {
  const fs::path dir = testing::ScratchDir("toss_pebble");
  SynthTruth truth;
  const KindScore k = RenderAndRun(dir,
                                   "--fps 26 --throw-right 1.2 --throw-up 1 --ball-x 0.05 --start-after-release 0.1 "
                                   "--duration 1.5 --floor-pattern pebble",
                                   "tennis", &truth);
  ExpectMustShow(k);
  const FlightScore f = TrackFlight(dir / "clip.avi", truth);
  EXPECT_EQ(f.lost, 0);
  EXPECT_LT(f.max_err, 2.0);
}

}  // namespace
}  // namespace bouncefit

