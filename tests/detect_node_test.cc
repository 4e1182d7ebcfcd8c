// The detect node over real LCM traffic (memq://): boxes in, calibration and peaks out, the
// same peaks as the core gives in-process; a garbled BALL_BOX packet is counted and ignored.
#include "detect/node/detect_node.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "msgs/lcm_bus.h"
#include "tests/detect_sim.h"
#include "track/node/capture_node.h"

namespace bouncefit {
namespace {

TEST(DetectNode, BoxesInPeaksOutOverMemq) {
  testing::SimOptions o;
  o.ball = "airball";
  o.drop_m = 1.2;
  o.roll_deg = 1;
  const auto clip = testing::MakeSimClip(o);

  // The core alone, in-process: the reference.
  BounceDetector core{BounceDetectorConfig{}};
  const auto expected = testing::RunDetector(core, clip.obs);
  ASSERT_GE(expected.size(), 5u);

  LcmBus bus("memq://");
  DetectNodeConfig cfg;
  DetectNode node(&bus, cfg);
  node.Subscribe();
  std::vector<bounce_peak_t> peaks;
  std::vector<calibration_t> cals;
  bus.Subscribe<bounce_peak_t>(cfg.channels.bounce_peak,
                               [&](const bounce_peak_t& m) { peaks.push_back(m); });
  bus.Subscribe<calibration_t>(cfg.channels.calibration,
                               [&](const calibration_t& m) { cals.push_back(m); });
  const uint8_t garbage[] = {0xde, 0xad, 0xbe, 0xef, 1, 2, 3};
  for (size_t i = 0; i < clip.obs.size(); ++i) {
    bus.Publish(cfg.channels.ball_box, ToBallBox(clip.obs[i]));
    if (i == 40) bus.raw().publish(cfg.channels.ball_box, garbage, sizeof garbage);
    bus.Drain();
  }
  node.Finish();
  bus.Drain();

  EXPECT_EQ(bus.decode_failures(), 1);
  EXPECT_EQ(node.stats().boxes, static_cast<int64_t>(clip.obs.size()));
  // Each apex live, then, when the drop ended, again with its height refitted with every arc
  // (the core's summary of the drop), at the live apex's pixel scale.
  ASSERT_FALSE(core.Summaries().empty());
  const SequenceSummary& drop = core.Summaries().back();
  ASSERT_GT(peaks.size(), expected.size());
  for (size_t i = expected.size(); i < peaks.size(); ++i) {
    const bounce_peak_t& r = peaks[i];
    const size_t k = static_cast<size_t>(r.bounce - drop.first_bounce);
    ASSERT_LT(k, drop.final_height_m.size());
    EXPECT_DOUBLE_EQ(r.height_m, drop.final_height_m[k]) << "bounce " << r.bounce;
    const auto live = std::find_if(peaks.begin(), peaks.begin() + static_cast<long>(expected.size()),
                                   [&](const bounce_peak_t& m) { return m.bounce == r.bounce; });
    ASSERT_NE(live, peaks.begin() + static_cast<long>(expected.size()));
    EXPECT_GE(r.emitted_utime, peaks[expected.size() - 1].emitted_utime);
    EXPECT_NEAR(r.height_px / r.height_m, live->height_px / live->height_m, 1e-6 * live->height_px / live->height_m);
  }
  EXPECT_GE(peaks.size() - expected.size(), expected.size() - 1);  // all but the release, at least
  peaks.resize(expected.size());
  for (size_t i = 0; i < peaks.size(); ++i) {
    EXPECT_EQ(peaks[i].bounce, expected[i].bounce);
    EXPECT_EQ(peaks[i].apex_utime, expected[i].apex_utime);
    EXPECT_DOUBLE_EQ(peaks[i].height_m, expected[i].height_m);
    EXPECT_EQ(peaks[i].emitted_utime, expected[i].emitted_utime);
  }
  const auto score = testing::ScorePeaks(clip, expected);
  EXPECT_EQ(score.found_over_1cm, score.truth_over_1cm) << score.report;
  EXPECT_EQ(score.false_peaks, 0) << score.report;
  ASSERT_FALSE(cals.empty());
  EXPECT_EQ(cals.back().method, "free-fall");
  EXPECT_NEAR(cals.back().px_per_m, o.px_per_m, 0.01 * o.px_per_m);
  EXPECT_NEAR(cals.back().roll_rad, o.roll_deg * M_PI / 180, 0.005);
}

TEST(DetectNode, TimeGoingBackwardsStartsAFreshStream) {
  testing::SimOptions o;
  o.ball = "softball";
  const auto clip = testing::MakeSimClip(o);
  DetectNode node(nullptr, DetectNodeConfig{});
  size_t peaks = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (const auto& b : clip.obs)
      for (const auto& e : node.OnObservation(b)) peaks += e.kind == DetectorEvent::Kind::kPeak;
  node.Finish();
  EXPECT_EQ(node.stats().stream_restarts, 1);
  const auto s = node.Summaries();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].peaks.size(), s[1].peaks.size());
  EXPECT_EQ(peaks, 2 * s[0].peaks.size());
}

}  // namespace
}  // namespace bouncefit
