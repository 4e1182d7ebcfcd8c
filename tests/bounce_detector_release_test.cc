// How a drop's first fall is followed when it is not the clean fall from rest the detector first
// assumes: a hand that pushes the ball down as it lets go, and a fall smeared into pixels of
// scatter at 24 fps. Every rebound must still be found, numbered from the release, and measured.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "detect/bounce_detector.h"
#include "detect_sim.h"

namespace bouncefit {
namespace {

using testing::FirstFall;

// The rebounds of `peaks` (bounce 1 and on) and the truth without the release's row: a release
// the detector cannot measure yet (a push) or at all (not the ball) is not scored.
std::pair<std::vector<BouncePeak>, testing::TruthApexes> Rebounds(const std::vector<BouncePeak>& peaks,
                                                                  testing::TruthApexes truth) {
  std::vector<BouncePeak> rebounds;
  for (const auto& p : peaks)
    if (p.bounce >= 1) rebounds.push_back(p);
  truth.apex_h_m[0] = 0;
  return {rebounds, truth};
}

class DetectorFirstFall : public ::testing::TestWithParam<FirstFall> {};

TEST_P(DetectorFirstFall, EveryReboundIsFoundNumberedAndMeasured) {
  const auto clip = testing::MakeFirstFallClip(GetParam());
  BounceDetectorConfig config;
  config.image_width_px = static_cast<int>(clip.options.width);
  config.image_height_px = static_cast<int>(clip.options.height);
  BounceDetector d{config};
  std::vector<DetectorEvent> events;
  const auto peaks = testing::RunDetector(d, clip.obs, &events);
  const auto truth = testing::TruthOf(clip);
  // Rebounds of 5 cm or more: a pushed release's own row is emitted before the push can be told
  // from gravity (docs/ACCURACY.md), so it is not scored here.
  const auto [rebounds, rebound_truth] = Rebounds(peaks, truth);
  const auto s = testing::ScorePeaks(rebound_truth, rebounds, 0.05);
  std::printf("%s", s.report.c_str());
  int ends = 0;
  for (const auto& e : events) ends += e.kind == DetectorEvent::Kind::kSequenceEnd;
  EXPECT_EQ(ends, 1) << "the drop broke\n" << s.report;
  ASSERT_FALSE(peaks.empty());
  EXPECT_EQ(peaks.front().bounce, 0) << s.report;
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  for (const auto& p : rebounds) {
    const auto b = static_cast<size_t>(p.bounce);
    if (b >= truth.apex_h_m.size() || truth.apex_h_m[b] < 0.05) continue;
    const double h = truth.apex_h_m[b];
    EXPECT_NEAR(p.height_m, h, std::max(0.002, 0.01 * h)) << "bounce " << b;
  }
}

// A first arc that was not the ball's flight. The ball is let go out of view above the picture
// and falls 2.5 m, a streak the tracker misses at 20 fps but in one frame; what it followed before
// that was a thing at the picture's top, still for five frames. The "release" arc made of the
// two lies tens of pixels off any fit and meets the first rebound's arc in mid-air. Its samples
// must not decide the scale (every rebound 12-21% low, the third taken for rest), nor that
// impact the floor under the later apexes.
TEST(DetectorFirstFall, AFirstArcThatWasNotTheBallLeavesTheReboundsAlone) {
  testing::SimOptions o;
  o.ball = "tennis";
  o.fps = 20;
  o.drop_m = 2.5;
  o.px_per_m = 220;
  o.noise_px = 0.5;
  o.exposure_frac = 0.5;
  o.width = 170, o.height = 486, o.floor_y = 478, o.x0 = 90;
  auto clip = testing::MakeSimClip(o);
  const double impact = clip.truth.impact_times_s.at(0);
  for (auto& b : clip.obs) {
    const double t = b.utime * 1e-6;
    if (t >= impact) continue;
    const double before = (impact - t) * o.fps;  // frames before the impact
    if (before > 3.5 && before < 7.5) {          // the thing at the top
      b.found = true;
      b.cx = static_cast<float>(o.x0), b.cy = 52;
      b.radius_px = static_cast<float>(clip.radius_px);
      b.x = b.cx - b.radius_px, b.y = b.cy - b.radius_px, b.w = b.h = 2 * b.radius_px;
    } else if (!(before > 2 && before < 3)) {
      b = {b.utime, b.frame};  // the streak, missed (or out of view)
    }
  }
  BounceDetectorConfig config;
  config.image_width_px = static_cast<int>(o.width);
  config.image_height_px = static_cast<int>(o.height);
  BounceDetector d{config};
  const auto peaks = testing::RunDetector(d, clip.obs);
  const auto truth = testing::TruthOf(clip);
  const auto [rebounds, rebound_truth] = Rebounds(peaks, truth);
  // Rebounds a flight of 4 frames at 20 fps can show (g T^2 / 8 = 5 cm) and more.
  const auto s = testing::ScorePeaks(rebound_truth, rebounds, 0.08);
  std::printf("%s", s.report.c_str());
  ASSERT_GE(s.truth_over_1cm, 4);
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  for (const auto& p : rebounds) {
    const auto b = static_cast<size_t>(p.bounce);
    if (b >= truth.apex_h_m.size() || truth.apex_h_m[b] < 0.08) continue;
    EXPECT_NEAR(p.height_m, truth.apex_h_m[b], 0.03 * truth.apex_h_m[b]) << "bounce " << b << "\n" << s.report;
  }
}

INSTANTIATE_TEST_SUITE_P(
    PushedOrSmeared, DetectorFirstFall,
    ::testing::Values(FirstFall{"tennis", 60, 0.6, 0, 1}, FirstFall{"tennis", 60, 0.6, 0, 2},
                      FirstFall{"basketball", 24, 0.6, 0, 1},
                      FirstFall{"basketball", 24, 0.6, 0, 2},
                      FirstFall{"pingpong", 120, 0.6, 0, 1}, FirstFall{"tennis", 60, 0.3, 0, 1},
                      FirstFall{"tennis", 24, 0, 2.5, 12}, FirstFall{"tennis", 24, 0, 2.5, 15},
                      FirstFall{"tennis", 24, 0, 2.5, 21}, FirstFall{"basketball", 24, 0, 2.5, 1},
                      // Broken until the sixteenth session: young falls their model lost (pushes
                      // at 24 fps, falls smeared slower than their first samples said), and a
                      // push the release-speed fit missed from the from-rest gravity (30 fps).
                      FirstFall{"tennis", 24, 0.3, 0, 4}, FirstFall{"pingpong", 24, 0, 2.5, 1},
                      FirstFall{"basketball", 24, 0, 2.5, 3},
                      FirstFall{"basketball", 24, 0.6, 0, 4}, FirstFall{"tennis", 30, 0.6, 0, 1},
                      // Its 2-3 cm hops after the drop ended at rest started a second drop, with
                      // a false row: the ball settling, lower than any apex a drop reports.
                      FirstFall{"pingpong", 24, 0, 0, 3}, FirstFall{"pingpong", 24, 0.3, 0, 1}),
    [](const ::testing::TestParamInfo<FirstFall>& i) {
      const auto& c = i.param;
      return c.ball + "_" + std::to_string(static_cast<int>(c.fps)) + "fps_" +
             (c.push_mps > 0      ? "pushed" + std::to_string(static_cast<int>(c.push_mps * 10)) + "dm_s"
              : c.fall_noise_px > 0 ? std::string("smeared")
                                    : std::string("from_rest")) +
             "_seed" + std::to_string(c.seed);
    });

}  // namespace
}  // namespace bouncefit
