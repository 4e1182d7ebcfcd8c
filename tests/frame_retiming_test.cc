// detect/frame_retiming.h: pictures taken at one rate and stamped at a lower one, re-timed
// from the ball's own flight.
#include "detect/frame_retiming.h"

#include <gtest/gtest.h>

#include <cmath>

#include "detect/bounce_detector.h"
#include "detect/retiming_detector.h"
#include "tests/detect_sim.h"

namespace bouncefit {
namespace {

using testing::MakeSimClip;
using testing::ScorePeaks;
using testing::SimClip;
using testing::SimOptions;

// A tennis drop seen at `taken_fps`, kept as a file at `stamped_fps`: the pictures nearest
// each stamp's slot (a frame-rate conversion that drops some), stamped evenly.
SimClip Restamped(double taken_fps, double stamped_fps, unsigned seed, double noise_px = 0.3) {
  SimOptions o;
  o.ball = "tennis";
  o.fps = taken_fps;
  o.noise_px = noise_px;
  o.seed = seed;
  SimClip c = MakeSimClip(o);
  std::vector<BallObservation> kept;
  for (int k = 0;; ++k) {
    const size_t n = static_cast<size_t>(std::floor(k * taken_fps / stamped_fps + 1e-9));
    if (n >= c.obs.size()) break;
    BallObservation b = c.obs[n];
    b.frame = k;
    b.utime = static_cast<int64_t>(std::llround(k / stamped_fps * 1e6));
    kept.push_back(b);
  }
  c.obs = kept;
  return c;
}

// The detector behind the test, as `run` and `detect` read: re-timed where the test finds a
// faster source rate (apply), or as stamped (--keep-frame-times).
std::vector<BouncePeak> Detect(const SimClip& c, bool apply, Retiming* retiming) {
  BounceDetectorConfig dc;
  dc.calibration.ball_diameter_m = ResolveBallPreset("tennis").diameter_m;
  FrameRetimingConfig rc;
  rc.mode = apply ? FrameTimes::kRetimed : FrameTimes::kStamped;
  RetimingDetector d(dc, rc);
  const auto peaks = testing::RunDetector(d, c.obs);
  *retiming = d.retiming();
  return peaks;
}

TEST(FrameRetiming, A24FpsCaptureStampedAt20FpsIsReadAtItsOwnTimes) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const SimClip c = Restamped(24, 20, seed);
    Retiming applied, reported;
    const auto retimed = ScorePeaks(c, Detect(c, true, &applied));
    const auto stamped = ScorePeaks(c, Detect(c, false, &reported));
    std::printf("seed %u: %s\n  re-timed: %d of %d apexes > 1 cm, %d false, worst %.2f mm; as stamped: %d, %d false, worst %.2f mm\n",
                seed, applied.verdict.c_str(), retimed.found_over_1cm, retimed.truth_over_1cm,
                retimed.false_peaks, retimed.max_err_mm, stamped.found_over_1cm, stamped.false_peaks,
                stamped.max_err_mm);
    ASSERT_TRUE(applied.applied) << applied.verdict;
    EXPECT_DOUBLE_EQ(applied.source_fps, 24);
    EXPECT_TRUE(reported.retimed) << "reported with --keep-frame-times too";
    EXPECT_FALSE(reported.applied);
    EXPECT_EQ(retimed.false_peaks, 0);
    // The apexes the detector resolves at 24 fps (above a 4-frame flight, 3.4 cm; it finds
    // all 6 of this drop on the 24 fps pictures all kept), but for one: with one picture in
    // six gone, the smallest arc may lack the samples it needs.
    const double four_frames_m = 9.81 * std::pow(4 / 24.0, 2) / 8;
    int resolvable = 0;
    for (double h : c.truth.apex_heights_m) resolvable += h >= four_frames_m;
    EXPECT_GE(retimed.found_over_1cm, resolvable - 1);
    EXPECT_TRUE(retimed.within_tolerance) << retimed.max_err_mm << " mm";
    EXPECT_GT(stamped.max_err_mm + 10 * (stamped.truth_over_1cm - stamped.found_over_1cm + stamped.false_peaks),
              3 * retimed.max_err_mm)
        << "the stamps alone do worse";
  }
}

TEST(FrameRetiming, AClipStampedAtTheRateItWasTakenIsLeftAlone) {
  for (double fps : {20.0, 25.0, 30.0, 60.0}) {
    SimOptions o;
    o.ball = "tennis";
    o.fps = fps;
    o.noise_px = 0.3;
    const SimClip c = MakeSimClip(o);
    Retiming r;
    const auto peaks = Detect(c, true, &r);
    const auto score = ScorePeaks(c, peaks);
    EXPECT_TRUE(r.decided);
    EXPECT_FALSE(r.retimed) << fps << " fps: " << r.verdict;
    EXPECT_EQ(score.false_peaks, 0) << fps << " fps";
    // Held while the test decided, then read as stamped: the rows of the detector alone.
    BounceDetectorConfig dc;
    dc.calibration.ball_diameter_m = ResolveBallPreset("tennis").diameter_m;
    BounceDetector alone(dc);
    const auto want = testing::RunDetector(alone, c.obs);
    ASSERT_EQ(peaks.size(), want.size()) << fps << " fps";
    for (size_t k = 0; k < peaks.size(); ++k) {
      EXPECT_EQ(peaks[k].bounce, want[k].bounce);
      EXPECT_EQ(peaks[k].height_m, want[k].height_m);
      EXPECT_EQ(peaks[k].emitted_utime, want[k].emitted_utime) << "emitted on the same picture";
    }
  }
}

// A smeared ball tracked to 1.5 px: the test fits whole arcs, so the noise does not hide the
// dropped pictures (a third difference over four samples, the test before, amplified it by
// the frame rate cubed), nor does it make honest stamps look dropped.
TEST(FrameRetiming, TheTestSurvivesTrackingNoise) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    Retiming r;
    Detect(Restamped(24, 20, seed, 1.5), false, &r);
    EXPECT_TRUE(r.retimed) << "seed " << seed << ": " << r.verdict;
    EXPECT_DOUBLE_EQ(r.source_fps, 24) << r.verdict;
    for (double fps : {20.0, 25.0, 30.0}) {
      SimOptions o;
      o.ball = "tennis";
      o.fps = fps;
      o.noise_px = 1.5;
      o.seed = seed;
      Retiming honest;
      Detect(MakeSimClip(o), false, &honest);
      EXPECT_TRUE(honest.decided);
      EXPECT_FALSE(honest.retimed) << fps << " fps, seed " << seed << ": " << honest.verdict;
    }
  }
}

TEST(FrameRetiming, UnevenStampsAreACapturesOwnAndPassStraightThrough) {
  FrameRetimingConfig rc;
  rc.mode = FrameTimes::kRetimed;
  FrameRetimer r(rc);
  BallObservation o;
  o.found = true;
  for (int i = 0; i < 30; ++i) {
    o.utime = static_cast<int64_t>(i * 33333 + (i % 3) * 2000);
    o.cy = static_cast<float>(100 + 3 * i * i);
    const auto out = r.Push(o);
    ASSERT_EQ(out.size(), 1u) << "frame " << i;
    EXPECT_EQ(out[0].utime, o.utime);
  }
  EXPECT_TRUE(r.retiming().decided);
  EXPECT_FALSE(r.retiming().retimed);
}

}  // namespace
}  // namespace bouncefit
