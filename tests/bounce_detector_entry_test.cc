// The bounce detector on drops whose start the camera did not see as a start: the ball first
// tracked in the middle of its fall, a few smeared frames before it hits the floor.
#include "detect/bounce_detector.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/detect_sim.h"

namespace bouncefit {
namespace {

using testing::MakeSimClip;
using testing::RunDetector;
using testing::ScorePeaks;
using testing::SimOptions;
using testing::SimTruth;

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
      // Its release apex is before the clip: not to be found. The first rebound is bounce 1,
      // or bounce 2 where the fall fits an arc, taken as one entered from out of view (its
      // apex unseen, as the detector numbers such an arc).
      auto truth = testing::TruthOf(clip);
      truth.apex_h_m[0] = 0;
      auto entered = truth;
      entered.apex_t_s.insert(entered.apex_t_s.begin() + 1, -100);
      entered.apex_h_m.insert(entered.apex_h_m.begin() + 1, 0);
      const double t5 = 5 / o.fps, min_m = 9.81 * t5 * t5 / 8;
      auto s = ScorePeaks(truth, peaks, min_m);
      if (!peaks.empty() && peaks.front().bounce == 2) s = ScorePeaks(entered, peaks, min_m);
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

}  // namespace
}  // namespace bouncefit
