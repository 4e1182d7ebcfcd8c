// The impact judge on a rendered drop stopped mid-flight (tests/detector_parts.h): rising
// samples after the truth's impact confirm it, a stray at their front is dropped, samples
// high above the floor are the arc's own, a hop of two samples at the floor gives way to the
// rebound after it, a falling arc's last sample off it straddles the impact.
#include <gtest/gtest.h>

#include <vector>

#include "detect/impact_judge.h"
#include "detect_sim.h"
#include "detector_parts.h"

namespace bouncefit {
namespace {

using testing::StoppedDrop;

// The rising samples judged below the stopped drop's current arc.
RisingVerdict Judge(const StoppedDrop& drop, std::vector<DetectorSample>& rising) {
  const ImpactJudge judge(drop.config, drop.host.scene, drop.arcs, drop.host);
  return judge.Judge(drop.arcs.arcs().back(), rising);
}

TEST(ImpactJudge, TwoRisingSamplesAfterTheTruthsImpactConfirmIt) {
  StoppedDrop drop;  // ping-pong, 1 m, 120 fps, 300 px/m
  const double impact = drop.clip.truth.impact_times_s[1];
  drop.Stop(impact - 0.5 * drop.frame());  // the first rebound falling to its impact
  ASSERT_TRUE(drop.host.scene.calibrated());
  ASSERT_EQ(drop.arcs.arcs().size(), 2u);
  const auto after = drop.After(impact + 0.5 * drop.frame(), 2);
  std::vector<DetectorSample> one{after[0]};
  EXPECT_EQ(Judge(drop, one), RisingVerdict::kWaiting);  // one sample confirms nothing
  EXPECT_EQ(one.size(), 1u);
  std::vector<DetectorSample> two = after;
  EXPECT_EQ(Judge(drop, two), RisingVerdict::kImpact);
  EXPECT_EQ(two.size(), 2u);
  // The newest not above the first: the first was a stray detection, dropped.
  std::vector<DetectorSample> stray = after;
  stray[0].y -= 20;
  EXPECT_EQ(Judge(drop, stray), RisingVerdict::kWaiting);
  ASSERT_EQ(stray.size(), 1u);
  EXPECT_EQ(stray[0].t, after[1].t);
}

TEST(ImpactJudge, RisingSamplesHighAboveTheFloorAreTheArcsOwn) {
  StoppedDrop drop;
  drop.Stop(drop.clip.truth.apex_times_s[1] + 3 * drop.frame());  // just past the apex
  ASSERT_EQ(drop.arcs.arcs().size(), 2u);
  std::vector<DetectorSample> rising = drop.After(drop.arcs.arcs().back().samples.back().t, 2);
  rising[0].y -= 10;
  rising[1].y -= 15;
  EXPECT_EQ(Judge(drop, rising), RisingVerdict::kOnTheArc);
}

TEST(ImpactJudge, AHopOfTwoSamplesAtTheFloorGivesWayToTheReboundAfterIt) {
  StoppedDrop drop;
  const double impact = drop.clip.truth.impact_times_s[1];
  drop.Stop(impact + 6 * drop.frame());  // the second rebound begun
  ASSERT_EQ(drop.arcs.arcs().size(), 3u);
  ASSERT_NE(drop.arcs.ImpactBeforeCurrent(), nullptr);
  const auto after = drop.After(impact + 0.5 * drop.frame(), 5);
  // Both frames either side of the impact showed the ball at the floor, taken for an arc.
  DetectorArc hop;
  hop.samples = {after[0], after[1]};
  for (auto& s : hop.samples) s.y = drop.clip.options.floor_y - drop.clip.radius_px;
  drop.arcs.arcs().back() = hop;
  std::vector<DetectorSample> rising{after[2], after[3]};
  EXPECT_EQ(Judge(drop, rising), RisingVerdict::kImpactAfterHop);
  // An arc of three samples is a flight of its own, whatever rises after it.
  drop.arcs.arcs().back().samples = {after[0], after[1], after[2]};
  rising = {after[3], after[4]};
  EXPECT_EQ(Judge(drop, rising), RisingVerdict::kImpact);
}

TEST(ImpactJudge, TheFallsLastSampleStraddlesTheImpactWhenOffTheFall) {
  StoppedDrop drop;
  drop.Stop(drop.clip.truth.impact_times_s[1] - 0.5 * drop.frame());
  const ImpactJudge judge(drop.config, drop.host.scene, drop.arcs, drop.host);
  DetectorArc fall = drop.arcs.arcs().back();
  ASSERT_GE(fall.samples.size(), 6u);
  EXPECT_FALSE(judge.LastSampleStraddles(fall));
  fall.samples.back().y -= 10;  // the exposure saw the ball fall and rise
  EXPECT_TRUE(judge.LastSampleStraddles(fall));
}

}  // namespace
}  // namespace bouncefit
