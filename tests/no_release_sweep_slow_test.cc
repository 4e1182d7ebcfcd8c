// A sweep of drops whose release is not seen or not a drop (every arc between two impacts is
// a bounce; bounce 0 only when the release is seen): 3 balls at 25-240 fps,
// thrown up (0.5-2 m/s) or sideways (0.4-1.2 m/s) from a seen hold, and clips that begin
// mid-bounce (0.5-1.5 s after the release), scale, drop height and roll drawn at random; the
// detector as `bouncefit run --ball B` configures it (picture and ball size known). Prints,
// per kind, the runs whole (every apex of 5 cm or more found, numbered as a person counts
// them, none false), broken drops, apexes missed, false peaks and rows beyond max(2 mm, 1%),
// and holds the counts measured when it was written.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "detect/bounce_detector.h"
#include "detect_sim.h"
#include "model/ball_preset.h"

namespace bouncefit {
namespace {

enum Kind { kThrownUp, kThrownSideways, kMidBounce, kKinds };
const char* kKindName[kKinds] = {"thrown up", "thrown sideways", "begun mid-bounce"};

struct Tally {
  int runs = 0, whole = 0, broken = 0, missed = 0, apexes = 0, false_peaks = 0, rows_off = 0, rows = 0;
};

TEST(NoReleaseSweep, ThrowsAndClipsBegunMidBounce) {
  Tally tally[kKinds];
  for (const char* ball : {"tennis", "pingpong", "basketball"}) {
    for (double fps : {25.0, 30.0, 60.0, 120.0, 240.0}) {
      for (int kind = 0; kind < kKinds; ++kind) {
        for (unsigned seed = 1; seed <= 4; ++seed) {
          std::mt19937 rng(seed * 1000 + static_cast<unsigned>(fps) + 7 * kind);
          std::uniform_real_distribution<double> u(0, 1);
          testing::SimOptions o;
          o.ball = ball;
          o.fps = fps;
          o.seed = seed;
          o.noise_px = 0.3;
          o.px_per_m = 250 + 150 * u(rng);
          o.drop_m = 0.8 + 0.7 * u(rng);
          o.roll_deg = 2 * u(rng) - 1;
          if (kind == kThrownUp) o.launch_up_mps = 0.5 + 1.5 * u(rng), o.launch_right_mps = 0.3 * u(rng);
          if (kind == kThrownSideways) o.launch_right_mps = 0.4 + 0.8 * u(rng), o.launch_up_mps = 0.3 * u(rng);
          if (kind == kMidBounce) o.begin_after_release_s = 0.5 + 1.0 * u(rng);
          if (o.launch_right_mps > 0) o.x0 = 100, o.width = 1000;
          const auto clip = testing::MakeSimClip(o);
          BounceDetectorConfig c;
          c.image_width_px = static_cast<int>(o.width);
          c.image_height_px = static_cast<int>(o.height);
          c.calibration.ball_diameter_m = ResolveBallPreset(ball).diameter_m;
          BounceDetector d{c};
          std::vector<DetectorEvent> events;
          const auto peaks = testing::RunDetector(d, clip.obs, &events);
          const auto truth = testing::TruthOf(clip);
          const auto s = testing::ScorePeaks(truth, peaks, 0.05);
          int ends = 0, off = 0, rows = 0;
          for (const auto& e : events) ends += e.kind == DetectorEvent::Kind::kSequenceEnd;
          for (const auto& p : peaks) {
            const auto b = static_cast<size_t>(p.bounce);
            if (b >= truth.apex_h_m.size() || truth.apex_h_m[b] < 0.05) continue;
            ++rows;
            off += std::abs(p.height_m - truth.apex_h_m[b]) > std::max(0.002, 0.01 * truth.apex_h_m[b]);
          }
          Tally& t = tally[kind];
          ++t.runs;
          t.whole += s.found_over_1cm == s.truth_over_1cm && s.false_peaks == 0;
          t.broken += ends > 1;
          t.missed += s.truth_over_1cm - s.found_over_1cm;
          t.apexes += s.truth_over_1cm;
          t.false_peaks += s.false_peaks;
          t.rows_off += off;
          t.rows += rows;
        }
      }
    }
  }
  for (int k = 0; k < kKinds; ++k)
    std::printf("%-17s %2d runs, %2d whole, %d broken, %2d of %3d apexes >= 5 cm missed, %2d false, "
                "%2d of %3d rows off\n",
                kKindName[k], tally[k].runs, tally[k].whole, tally[k].broken, tally[k].missed,
                tally[k].apexes, tally[k].false_peaks, tally[k].rows_off, tally[k].rows);
  // The bounds are the measured counts (docs/ACCURACY.md "Rendered drops (synth truth)"). The
  // begun mid-bounce runs not whole: a clip begun 2 frames before a rebound's apex at 120 fps and 8 at 240 fps
  // (the rise into it within a hold's jitter: taken for a release, bounce 0, every rebound
  // numbered one too low), one begun 0.7 frames after it (its vertex taken for a release out
  // of sight), and one with two false 1-2 cm hops.
  EXPECT_GE(tally[kThrownUp].whole, 59);
  EXPECT_GE(tally[kThrownSideways].whole, 59);
  EXPECT_GE(tally[kMidBounce].whole, 56);
  EXPECT_EQ(tally[kThrownUp].missed + tally[kThrownSideways].missed, 0);
  EXPECT_LE(tally[kThrownUp].broken, 5);
}

}  // namespace
}  // namespace bouncefit
