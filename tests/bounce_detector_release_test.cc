// How a drop's first fall is followed when it is not the clean fall from rest the detector first
// assumes: a hand that pushes the ball down as it lets go, and a fall smeared into pixels of
// scatter at 24 fps. Every rebound must still be found, numbered from the release, and measured.
#include <gtest/gtest.h>

#include <string>

#include "detect/bounce_detector.h"
#include "detect_sim.h"

namespace bouncefit {
namespace {

using testing::FirstFall;

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
  std::vector<BouncePeak> rebounds;
  for (const auto& p : peaks)
    if (p.bounce >= 1) rebounds.push_back(p);
  testing::TruthApexes rebound_truth = truth;
  rebound_truth.apex_h_m[0] = 0;
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
