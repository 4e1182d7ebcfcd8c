// The bounce detector on drops whose start the camera did not see as a start: a release at
// the first frame, a hold never seen, a throw, a clip that begins mid-bounce, a ball first
// tracked in the middle of its fall, smeared first arcs at 24 fps.
#include "detect/bounce_detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "tests/detect_sim.h"

namespace bouncefit {
namespace {

using testing::MakeSimClip;
using testing::RunDetector;
using testing::ScorePeaks;
using testing::SimOptions;
using testing::SimTruth;

// A ball thrown away from the camera enters the view falling and accelerates at 0.55 of
// gravity over its 7 frames before an impact (a 30 fps clip of a tennis ball thrown across a
// wooden floor measured 3 000 px/s^2 there, 5 600 on its rebounds; only that acceleration is
// rendered here). The scale that short arc gives is the only one until a rebound arc grows:
// each new rising sample, judged against it, must not push the arc's first ones out (before,
// the rebound's arc stayed at three to five samples and the drop broke or ended "at rest").
TEST(BounceDetector, AShortFirstArcThatMeasuresGravityLowDoesNotBreakTheRebounds) {
  SimOptions o;
  o.ball = "tennis";
  o.drop_m = 1.5;
  o.fps = 30;
  o.px_per_m = 570;  // 38 px across
  o.noise_px = 0.3;
  o.launch_right_mps = 0.5;
  o.floor_y = 900;
  o.height = 960;
  o.width = 1400;
  o.x0 = 100;
  o.hold_s = 0;
  // It enters on the fall after its first rebound's apex: the first apex in view, after the
  // next impact, is bounce 1 to the detector (it cannot know how many came before).
  const double impact = SimTruth(o).impact_times_s[1];
  o.begin_after_release_s = impact - 7.5 / o.fps;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    o.seed = seed;
    auto clip = MakeSimClip(o);
    const double g_px = 9.81 * o.px_per_m, k = 0.55;
    for (auto& ob : clip.obs) {
      const double t = (ob.utime - clip.obs.front().utime) * 1e-6 + o.begin_after_release_s;
      if (ob.found && t < impact)
        ob.cy += static_cast<float>(0.5 * (k - 1) * g_px * (t - impact) * (t - impact));
    }
    BounceDetector d{BounceDetectorConfig{}};
    const auto peaks = RunDetector(d, clip.obs);
    const auto truth = testing::TruthOf(clip);
    const double t4 = 4 / o.fps;
    const auto s = ScorePeaks(truth, peaks, 9.81 * t4 * t4 / 8);
    std::printf("seed %u: %d of %d apexes over a 4-frame flight, %d false, %zu drop(s), max error %.1f mm\n%s",
                seed, s.found_over_1cm, s.truth_over_1cm, s.false_peaks, d.Summaries().size(),
                s.max_err_mm, s.report.c_str());
    EXPECT_EQ(s.false_peaks, 0) << s.report;
    EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
    EXPECT_GE(s.truth_over_1cm, 5) << s.report;
    EXPECT_EQ(d.Summaries().size(), 1u) << "the drop broke\n" << s.report;
    // The first rebound is emitted on a scale still pulled by the entering arc (2-3% low) and
    // a floor placed by it: +4-5% on these seeds; the rebounds after it within 5% too.
    for (const auto& p : peaks) {
      const auto b = static_cast<size_t>(p.bounce);
      if (b < truth.apex_h_m.size() && truth.apex_h_m[b] > 0) {
        EXPECT_NEAR(p.height_m, truth.apex_h_m[b], 0.06 * truth.apex_h_m[b]) << b << "\n" << s.report;
      }
    }
  }
}

// A ball released from a seen hold at 30 fps is seen for four frames of its fall (smeared,
// then lost to the tracker until it rebounds), and those bend 16% more than gravity (a phone's
// rolling shutter reads a fall down the picture late). The scale from that fall is 16% high,
// known to some 7%; the first rebound, followed with it, leaves its arc within a few samples
// unless the gate carries the scale's uncertainty (a cropped copy of the shared green-ball
// clip lost its first rebound and broke its drop this way).
TEST(BounceDetector, AFirstFallThatMeasuresGravityHighDoesNotBreakTheFirstRebound) {
  SimOptions o;
  o.ball = "tennis";
  o.drop_m = 0.75;
  o.fps = 30;
  o.px_per_m = 1240;  // 83 px across
  o.noise_px = 1.5;   // a smeared ball at 30 fps, located to a pixel or two
  o.floor_y = 1040;
  o.height = 1080;
  o.width = 1920;
  o.x0 = 980;
  o.hold_s = 0.5;
  const double impact = SimTruth(o).impact_times_s[0];
  const auto clip_truth = MakeSimClip(o);  // the heights do not depend on the noise's seed
  auto run = [&](unsigned seed, double scale_gate_sigmas, std::string* report) {
    o.seed = seed;
    auto clip = MakeSimClip(o);
    const double g_px = 9.81 * o.px_per_m, k = 1.16;
    for (auto& ob : clip.obs) {
      const double ts = (ob.utime - clip.obs.front().utime) * 1e-6;  // stream time
      const double t = ts - o.hold_s;                                     // from the release
      if (!ob.found || t <= 0 || ts >= impact) continue;
      if (t > 4.5 / o.fps) ob.found = false;
      else ob.cy += static_cast<float>(0.5 * (k - 1) * g_px * t * t);
    }
    BounceDetectorConfig config;
    config.scale_gate_sigmas = scale_gate_sigmas;
    BounceDetector d{config};
    const auto peaks = RunDetector(d, clip.obs);
    const double t5 = 5 / o.fps;
    const auto s = ScorePeaks(testing::TruthOf(clip), peaks, 9.81 * t5 * t5 / 8);
    *report = s.report;
    std::printf("seed %u, scale gate %.0f sigmas: %d of %d apexes over a 5-frame flight, %d false, %zu drop(s)\n%s",
                seed, scale_gate_sigmas, s.found_over_1cm, s.truth_over_1cm, s.false_peaks,
                d.Summaries().size(), s.report.c_str());
    return std::make_tuple(s, d.Summaries().size(), peaks);
  };
  // Whole: one drop, every apex over a 5-frame flight, no false one.
  auto whole = [](const auto& s, size_t drops) {
    return drops == 1 && s.false_peaks == 0 && s.found_over_1cm == s.truth_over_1cm;
  };
  int whole_with = 0, whole_without = 0;
  const auto truth = testing::TruthOf(clip_truth);
  for (unsigned seed = 1; seed <= 6; ++seed) {
    std::string report;
    const auto [s, drops, peaks] = run(seed, BounceDetectorConfig{}.scale_gate_sigmas, &report);
    EXPECT_EQ(s.false_peaks, 0) << report;
    EXPECT_GE(s.truth_over_1cm, 4) << report;
    whole_with += whole(s, drops);
    // The first rebound, when emitted in this drop, on the fall's scale refitted with its own
    // arc: within 5%.
    for (const auto& p : peaks) {
      if (p.bounce == 1 && p.sequence == 0) {
        EXPECT_NEAR(p.height_m, truth.apex_h_m[1], 0.05 * truth.apex_h_m[1]) << report;
      }
    }
    const auto [s0, drops0, peaks0] = run(seed, 0, &report);
    whole_without += whole(s0, drops0);
  }
  // The scale's uncertainty the fit reports is its noise (4-5% here): a 16% bias at 3 sigmas
  // still breaks the drop on half the seeds (docs/ACCURACY.md).
  std::printf("whole drops over 6 seeds: %d with the scale's uncertainty in the gate, %d without\n",
              whole_with, whole_without);
  EXPECT_GT(whole_with, whole_without);
  EXPECT_GE(whole_with, 3);
}

// A ping-pong ball at 30 fps (a phone's clip, 92 px across), first found four frames before
// it hits the floor, the first of them smeared 25 px short of the fall (the tracker's first
// sighting of a streak). That fall starts no drop: it fits no parabola. The first arc is
// then the rebound, entered from its impact; the sample at the bottom of the V (the last
// before the impact, on the fall) fitted with the rebound's first four bends it a third more
// than gravity, and the arc, followed with that bend, left its samples at its apex: the drop
// broke before it was calibrated and the first rebounds were lost (a copy of the shared
// ping-pong ruler clip cropped by 8 px: its first three rebounds). Every phase of the frames
// against the impact, three seeds each: 11 of the 12 drops whole (8 before).
TEST(BounceDetectorEntry, ABallFirstSeenMidFallKeepsItsFirstRebounds) {
  SimOptions o;
  o.ball = "pingpong";
  o.drop_m = 0.35;
  o.fps = 30;
  o.px_per_m = 2300;
  o.noise_px = 1.0;
  o.floor_y = 1000;
  o.height = 1034;
  o.width = 864;
  o.x0 = 450;
  o.hold_s = 0;
  const double impact = SimTruth(o).impact_times_s[0];
  int whole = 0, runs = 0;
  for (double phase : {0.0, 0.25, 0.5, 0.75}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      o.seed = seed;
      o.begin_after_release_s = impact - (4 + phase) / o.fps;
      auto clip = MakeSimClip(o);
      for (auto& ob : clip.obs)
        if (ob.found) {
          ob.cy -= 25;  // the first sighting only
          break;
        }
      BounceDetector d{BounceDetectorConfig{}};
      const auto peaks = RunDetector(d, clip.obs);
      // Its release apex is before the clip: not to be found. The first rebound, the first
      // apex in view, is bounce 1 (it was bounce 2 where the fall fitted an arc taken as one
      // entered from out of view, its unseen apex counted).
      auto truth = testing::TruthOf(clip);
      truth.apex_h_m[0] = 0;
      const double t5 = 5 / o.fps, min_m = 9.81 * t5 * t5 / 8;
      const auto s = ScorePeaks(truth, peaks, min_m);
      std::printf("phase %.2f frame, seed %u: %d of %d apexes over a 5-frame flight, %d false, %zu drop(s), max error %.1f mm\n%s",
                  phase, seed, s.found_over_1cm, s.truth_over_1cm, s.false_peaks, d.Summaries().size(),
                  s.max_err_mm, s.report.c_str());
      EXPECT_GE(s.truth_over_1cm, 4) << s.report;
      ++runs;
      whole += d.Summaries().size() == 1 && s.found_over_1cm == s.truth_over_1cm && s.false_peaks == 0;
    }
  }
  // One drop is still not whole: at phase 0, seed 3, the four frames of the fall (the first
  // 25 px off) are taken for a fall from an unseen release whose vertex is fitted 0.67 m up,
  // a false bounce 0, and the drop breaks at the impact. That is the fall's start, not the V's
  // bottom; it fails the same way with the bottom kept (docs/ACCURACY.md).
  std::printf("whole drops, every apex found and none false: %d of %d\n", whole, runs);
  EXPECT_GE(whole, runs - 1);
}

TEST(BounceDetector, ReleaseAtTheFirstFrameWithoutAHold) {
  testing::SimOptions o;
  o.ball = "airball";
  o.drop_m = 1.4;
  o.hold_s = 0;
  const auto clip = testing::MakeSimClip(o);
  BounceDetector d{BounceDetectorConfig{}};
  const auto s = testing::ScorePeaks(clip, testing::RunDetector(d, clip.obs));
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  EXPECT_TRUE(s.within_tolerance) << s.report;
}

// `bouncefit run` without --color: the tracker locks on the ball only once it moves, a few
// frames after the release, so the hold is never seen. The release arc is then a fall from
// rest whose start was missed: bounce 0 is its fitted vertex, the rebounds are as usual.
struct UnseenHold {
  std::string ball;
  int frames_missed;  // frames after the release with no detection
  double roll_deg;
};

void PrintTo(const UnseenHold& c, std::ostream* os) {
  *os << c.ball << ", " << c.frames_missed << " frames missed, roll " << c.roll_deg;
}

class DetectorUnseenHold : public ::testing::TestWithParam<UnseenHold> {};

TEST_P(DetectorUnseenHold, ReleaseHeightIsTheVertexOfTheFall) {
  const UnseenHold c = GetParam();
  testing::SimOptions o;
  o.ball = c.ball;
  o.drop_m = 1.0;
  o.roll_deg = c.roll_deg;
  o.hold_s = 0.5;
  o.seed = static_cast<unsigned>(3 + c.frames_missed);
  // Nothing seen during the hold nor the first frames of the fall.
  o.gaps = {{0.0, o.hold_s + (c.frames_missed + 0.5) / o.fps}};
  const auto clip = testing::MakeSimClip(o);
  BounceDetector d{BounceDetectorConfig{}};
  const auto peaks = testing::RunDetector(d, clip.obs);
  const auto s = testing::ScorePeaks(clip, peaks);
  std::printf("%s", s.report.c_str());
  ASSERT_FALSE(peaks.empty()) << "no peak at all";
  EXPECT_EQ(peaks.front().bounce, 0) << s.report;
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  EXPECT_TRUE(s.within_tolerance) << s.report;
  EXPECT_TRUE(d.calibrated());
  EXPECT_LT(std::abs(d.calibration().px_per_m / o.px_per_m - 1), 0.01);
}

INSTANTIATE_TEST_SUITE_P(
    FirstFramesAfterReleaseMissed, DetectorUnseenHold,
    ::testing::Values(UnseenHold{"softball", 5, 0}, UnseenHold{"softball", 2, 1.5},
                      UnseenHold{"softball", 8, 0}, UnseenHold{"wiffle", 5, -1},
                      UnseenHold{"wiffle", 2, 0}, UnseenHold{"wiffle", 3, 0},
                      UnseenHold{"airball", 5, 0}),
    [](const ::testing::TestParamInfo<UnseenHold>& i) {
      return i.param.ball + "_" + std::to_string(i.param.frames_missed) + "_frames_missed";
    });

// A finder that sees what moves finds a still ball only once it falls, the later the more
// the camera shakes (a hand-held phone: 0.1 s after the release at 30 fps). A fall first seen
// that late after its vertex was taken for an arc entered from out of view, its rebounds
// numbered from 2. With the picture's size known, a vertex inside it and nothing seen rising
// into it while the camera watched make it a release: bounce 0 is its vertex, then 1, 2, ...
// The detector as `bouncefit run` configures it: the picture's size known.
BounceDetectorConfig AsRunConfiguresIt(const testing::SimOptions& o) {
  BounceDetectorConfig config;
  config.image_width_px = static_cast<int>(o.width);
  config.image_height_px = static_cast<int>(o.height);
  return config;
}

struct LateFall {
  std::string ball;
  double fps;
  int frames_missed;  // frames after the release with no detection
  // Heights within max(2 mm, 1%). Not yet for a light ball: the scale its fall gives before
  // the rebound (drag not told from gravity on one arc without its vertex, so held at none)
  // is 10% low, and the first rows, emitted on the scale of the fall and half a rebound, come
  // out 1.3-1.5% (release) and 1.1-1.4% (first rebound) high (ping-pong, wiffle ball at 30
  // fps; docs/ACCURACY.md).
  bool heights_checked = true;
};

void PrintTo(const LateFall& c, std::ostream* os) {
  *os << c.ball << " at " << c.fps << " fps, " << c.frames_missed << " frames missed";
}

class DetectorLateFall : public ::testing::TestWithParam<LateFall> {};

testing::SimOptions LateFallOptions(const LateFall& c) {
  testing::SimOptions o;
  o.ball = c.ball;
  o.fps = c.fps;
  o.drop_m = 1.0;
  o.hold_s = 0.5;
  o.noise_px = 0.3;
  o.seed = static_cast<unsigned>(c.fps + c.frames_missed);
  o.gaps = {{0.0, o.hold_s + (c.frames_missed + 0.5) / o.fps}};
  return o;
}

TEST_P(DetectorLateFall, AFallFirstSeenAfterItsVertexInViewIsARelease) {
  const testing::SimOptions o = LateFallOptions(GetParam());
  const auto clip = testing::MakeSimClip(o);
  BounceDetector d{AsRunConfiguresIt(o)};
  const auto peaks = testing::RunDetector(d, clip.obs);
  // Every apex of a flight of 5 frames or more (the shortest, at 4, are the detector's limit).
  const double t5 = 5 / o.fps;
  const auto s = testing::ScorePeaks(testing::TruthOf(clip), peaks, std::max(0.01, 9.81 * t5 * t5 / 8));
  std::printf("%s", s.report.c_str());
  ASSERT_FALSE(peaks.empty());
  EXPECT_EQ(peaks.front().bounce, 0) << s.report;
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  if (GetParam().heights_checked) {
    EXPECT_TRUE(s.within_tolerance) << s.report;
  }
}

// The same fall with its vertex above the picture's top (the ball dropped from out of view):
// no release height is reported, the apex was never in view.
TEST_P(DetectorLateFall, AFallFromAboveThePictureHasNoReleaseRow) {
  testing::SimOptions o = LateFallOptions(GetParam());
  // The ball whole in view only after falling 0.2 s from its vertex, the floor in view.
  const double enters_s = 0.2, radius_px = ResolveBallPreset(o.ball).diameter_m / 2 * o.px_per_m;
  o.floor_y = radius_px - 0.5 * 9.81 * enters_s * enters_s * o.px_per_m + (o.drop_m * o.px_per_m + radius_px);
  o.gaps = {{0.0, o.hold_s + std::max(enters_s, (GetParam().frames_missed + 0.5) / o.fps)}};
  const auto clip = testing::MakeSimClip(o);
  BounceDetector d{AsRunConfiguresIt(o)};
  const auto peaks = testing::RunDetector(d, clip.obs);
  ASSERT_FALSE(peaks.empty());
  for (const auto& p : peaks) EXPECT_NE(p.bounce, 0) << "a release height out of view";
}

INSTANTIATE_TEST_SUITE_P(
    HandHeldLock, DetectorLateFall,
    ::testing::Values(LateFall{"tennis", 30, 3}, LateFall{"pingpong", 30, 3, false},
                      LateFall{"softball", 24, 3}, LateFall{"tennis", 60, 7},
                      LateFall{"basketball", 30, 5}, LateFall{"wiffle", 30, 3, false}),
    [](const ::testing::TestParamInfo<LateFall>& i) {
      return i.param.ball + "_" + std::to_string(static_cast<int>(i.param.fps)) + "fps_" +
             std::to_string(i.param.frames_missed) + "_missed";
    });

// No release needed. A throw (vertical and horizontal launch speed), a clip that
// begins mid-bounce, from 25 to 240 fps, with the exposure half the frame period (1/60 s at
// 30 fps: the centre is the exposure average); every apex found within max(2 mm, 1%), no
// false peak, and promptly (median <= 2 and max <= 4 frames after the apex).
struct Motion {
  std::string name;
  std::string ball;
  double drop_m, fps, up_mps, right_mps, begin_s;
  // Instead of begin_s: the clip begins this many frames before the first rebound's apex
  // (negative: after it).
  double frames_before_apex = NAN;
  bool size_known = false;  // the ball's size given, as `run --ball` gives it
};

void PrintTo(const Motion& m, std::ostream* os) { *os << m.name; }

class DetectorMotionKinds : public ::testing::TestWithParam<Motion> {};

TEST_P(DetectorMotionKinds, EveryApexWithoutARelease) {
  const Motion m = GetParam();
  testing::SimOptions o;
  o.ball = m.ball;
  o.drop_m = m.drop_m;
  o.fps = m.fps;
  o.launch_up_mps = m.up_mps;
  o.launch_right_mps = m.right_mps;
  o.begin_after_release_s = m.begin_s;
  o.x0 = 150;
  o.width = 900;
  o.seed = static_cast<unsigned>(m.fps + 7);
  if (std::isfinite(m.frames_before_apex))
    o.begin_after_release_s = testing::MakeSimClip(o).truth.apex_times_s.at(1) - m.frames_before_apex / m.fps;
  const auto clip = testing::MakeSimClip(o);
  BounceDetectorConfig config = AsRunConfiguresIt(o);  // as `bouncefit run` gives it
  if (m.size_known) config.calibration.ball_diameter_m = ResolveBallPreset(m.ball).diameter_m;
  BounceDetector d{config};
  const auto peaks = testing::RunDetector(d, clip.obs);
  // Required: every apex whose flight lasts 4 frames or more (g T^2 / 8; 2.2 cm at 30 fps),
  // and at least 1 cm (the detector reports no shorter hop: its apex is not measurable).
  const double t4 = 4 / m.fps;
  auto s = testing::ScorePeaks(testing::TruthOf(clip), peaks, std::max(0.01, 9.81 * t4 * t4 / 8));
  // The arc a clip begins with (mid-flight) waits for the floor, like a release height:
  // its apex goes out at the first impact, so it is left out of the latency.
  if (o.begin_after_release_s > 0 && !s.latency_frames.empty()) s.latency_frames.erase(s.latency_frames.begin());
  const double med = testing::Median(s.latency_frames), mx = testing::MaxOf(s.latency_frames);
  std::printf("%s%s: %d/%d apexes, %d false, max err %.2f mm, latency median %.2f max %.2f "
              "frames\n",
              s.report.c_str(), m.name.c_str(), s.found_over_1cm, s.truth_over_1cm, s.false_peaks,
              s.max_err_mm, med, mx);
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  EXPECT_TRUE(s.within_tolerance) << s.report;
  EXPECT_LE(med, 2.0) << s.report;
  EXPECT_LE(mx, 4.0) << s.report;
  EXPECT_LT(std::abs(d.calibration().px_per_m / o.px_per_m - 1), 0.01);
}

INSTANTIATE_TEST_SUITE_P(
    NoRelease, DetectorMotionKinds,
    ::testing::Values(Motion{"dropped_30fps", "tennis", 1.0, 30, 0, 0, 0},
                      Motion{"dropped_25fps", "basketball", 1.2, 25, 0, 0, 0},
                      Motion{"thrown_up_60fps", "tennis", 0.8, 60, 1.5, 0.3, 0},
                      Motion{"thrown_sideways_30fps", "tennis", 1.0, 30, 0, 0.8, 0},
                      Motion{"thrown_up_240fps", "pingpong", 0.6, 240, 1.0, 0.2, 0},
                      Motion{"midbounce_rising_30fps", "tennis", 1.0, 30, 0, 0, 0.6},
                      Motion{"midbounce_falling_120fps", "football", 1.0, 120, 0, 0, 1.1},
                      Motion{"midbounce_25fps", "basketball", 1.5, 25, 0, 0.2, 0.9},
                      // A throw's first frame 17 px up, smeared, the hand's last still: the
                      // ball left the hand between them (it was numbered a rebound).
                      Motion{"thrown_up_30fps_from_the_hand", "pingpong", 1.3, 30, 1.6, 0.1, 0},
                      // Begun 6 frames before a rebound's apex at 120 fps: within a hold's
                      // jitter until the apex, it was taken for a hand (a false bounce 0 and
                      // every rebound numbered one too low).
                      Motion{"midbounce_6_frames_before_apex_120fps", "tennis", 1.3, 120, 0, 0, 0, 6},
                      // Begun 2 frames after it: the vertex before the first frame.
                      Motion{"midbounce_2_frames_after_apex_120fps", "tennis", 1.2, 120, 0, 0, 0, -2}),
    [](const ::testing::TestParamInfo<Motion>& i) { return i.param.name; });

// A ball thrown across the floor, unseen for the six frames around its first impact (at 30 fps)
// while the tracker holds a lookalike standing at the picture's edge, far across from where the
// ball could have gone. Those are not the ball's samples off its arc: the drop waits as if the
// ball were unseen. Before, the fall's prediction ran on past the floor, its reach with it, and
// the six lookalike frames counted as misses that ended the drop (the thrown arc and its apex
// lost; a clip of other people's).
TEST(BounceDetector, ALookalikeAtTheEdgeWhileTheBallBouncesUnseenDoesNotEndTheDrop) {
  testing::SimOptions o;
  o.ball = "tennis";
  o.drop_m = 0.7;
  o.fps = 30;
  o.launch_up_mps = 1.2;
  o.launch_right_mps = 0.6;
  o.begin_after_release_s = 0.1;  // thrown from out of view: no hold
  o.px_per_m = 250;
  o.x0 = 60, o.width = 320, o.floor_y = 230, o.height = 240;
  o.seed = 37;
  auto clip = testing::MakeSimClip(o);
  const double impact = clip.truth.impact_times_s.at(0) - o.begin_after_release_s;
  // Where the lookalike is, frame by frame: still but for the jitter of its detection.
  const float at[6][2] = {{6, 132}, {7, 135}, {7, 137}, {7, 144}, {7, 135}, {12, 162}};
  int lookalike = 0;
  for (auto& b : clip.obs) {
    const double frames = (b.utime * 1e-6 - impact) * o.fps;  // from the impact
    if (frames < -1 || frames >= 5) continue;
    b.found = true;
    b.cx = at[lookalike][0], b.cy = at[lookalike][1];
    b.radius_px = static_cast<float>(clip.radius_px);
    b.x = b.cx - b.radius_px, b.y = b.cy - b.radius_px, b.w = b.h = 2 * b.radius_px;
    ++lookalike;
  }
  ASSERT_EQ(lookalike, 6);
  BounceDetector d{AsRunConfiguresIt(o)};
  std::vector<DetectorEvent> events;
  const auto peaks = testing::RunDetector(d, clip.obs, &events);
  const double t4 = 4 / o.fps;
  const auto s = testing::ScorePeaks(testing::TruthOf(clip), peaks, 9.81 * t4 * t4 / 8);
  std::printf("%s", s.report.c_str());
  int broken = 0;
  for (const auto& e : events) broken += e.kind == DetectorEvent::Kind::kSequenceEnd && e.reason == "broken";
  EXPECT_EQ(broken, 0) << s.report;
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  EXPECT_TRUE(s.within_tolerance) << s.report;
}

// A ball 120 px across filmed at 24 fps is located to a pixel or two (here 2 px), not to the
// 0.3 px the detector assumes before its first fit: the first arc must start all the same
// (the start gate grows with the ball's radius). Without that share half of these apexes are
// lost (printed below).
TEST(BounceDetector, ALargeSmearedBallEnteringMidBounceStartsItsFirstArc) {
  testing::SimOptions o;
  o.ball = "pingpong";
  o.drop_m = 0.3;
  o.fps = 24;
  o.px_per_m = 3000;  // radius 60 px
  o.noise_px = 2.0;   // 3% of the radius
  o.begin_after_release_s = 0.33;
  o.height = 1300;
  o.floor_y = 1200;
  o.width = 900;
  o.x0 = 450;
  o.after_rest_s = 0.3;
  int found_without = 0;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    o.seed = seed;
    const auto clip = testing::MakeSimClip(o);
    BounceDetector d{BounceDetectorConfig{}};
    const auto peaks = testing::RunDetector(d, clip.obs);
    const double t4 = 4 / o.fps;
    const auto s = testing::ScorePeaks(testing::TruthOf(clip), peaks, std::max(0.01, 9.81 * t4 * t4 / 8));
    std::printf("seed %u: %d/%d apexes, %d false, max err %.2f mm\n", seed, s.found_over_1cm,
                s.truth_over_1cm, s.false_peaks, s.max_err_mm);
    EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
    EXPECT_EQ(s.false_peaks, 0) << s.report;
    EXPECT_GE(s.truth_over_1cm, 3);

    BounceDetectorConfig fixed;
    fixed.initial_noise_radius_share = 0;
    BounceDetector without{fixed};
    found_without += testing::ScorePeaks(testing::TruthOf(clip), testing::RunDetector(without, clip.obs),
                                         std::max(0.01, 9.81 * t4 * t4 / 8)).found_over_1cm;
  }
  std::printf("with the start gate fixed at 0.3 px noise: %d apexes found in the 4 clips\n", found_without);
}

// A phone's 24 fps with a long exposure (half or all of the frame period), a ping-pong ball 88 px
// across dropped from 30 cm held still: a fall of six frames, rebounds of four to eight, and the
// frames either side of each impact both smeared near the floor. Every arc must still be
// followed: the fall from the hold from its first two samples (the third is tens of pixels
// further), a rebound whose first sample straddles its impact, two frames at the floor that
// are one impact, not a hop. Before these, the detector found 94 of these 352 apexes.
TEST(BounceDetector, APingPongDropAt24FpsWithLongExposureIsFollowedBounceByBounce) {
  int found = 0, truth = 0;
  double ss_mm = 0;
  int rebounds = 0;
  for (double noise_px : {0.5, 1.0}) {
    for (double exposure : {0.5, 1.0}) {
      for (unsigned seed = 1; seed <= 8; ++seed) {
        testing::SimOptions o;
        o.ball = "pingpong";
        o.drop_m = 0.3;
        o.fps = 24;
        o.px_per_m = 2200;  // radius 44 px
        o.noise_px = noise_px;
        o.exposure_frac = exposure;
        o.height = 1300;
        o.floor_y = 1200;
        o.width = 900;
        o.x0 = 450;
        o.seed = seed;
        o.hold_s = 0.3 + seed * 0.0037;  // the release at a different phase of the frames
        const auto clip = testing::MakeSimClip(o);
        BounceDetectorConfig config;
        config.calibration.ball_diameter_m = 0.04;  // as `run --ball pingpong` gives it
        BounceDetector d{config};
        const auto peaks = testing::RunDetector(d, clip.obs);
        const double t4 = 4 / o.fps;  // apexes of flights shorter than 4 frames are not required
        const auto s = testing::ScorePeaks(testing::TruthOf(clip), peaks, 9.81 * t4 * t4 / 8);
        SCOPED_TRACE("noise " + std::to_string(noise_px) + " px, exposure " +
                     std::to_string(exposure) + ", seed " + std::to_string(seed));
        EXPECT_EQ(s.false_peaks, 0) << s.report;
        EXPECT_GE(s.found_over_1cm, s.truth_over_1cm - 1) << s.report;
        found += s.found_over_1cm;
        truth += s.truth_over_1cm;
        ss_mm += s.rms_err_rebounds_mm * s.rms_err_rebounds_mm * s.rebounds;
        rebounds += s.rebounds;
      }
    }
  }
  std::printf("24 fps, long exposure: %d of %d apexes found; rebound heights %.2f mm RMS\n", found,
              truth, std::sqrt(ss_mm / std::max(1, rebounds)));
  EXPECT_GE(found, truth - 4);
}

}  // namespace
}  // namespace bouncefit
