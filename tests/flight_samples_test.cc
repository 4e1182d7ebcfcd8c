// The samples of a rendered drop in flight (tests/detector_parts.h), taken back by the arcs
// closed by its impacts: those an arc lost come back in time order, not those within a frame
// of an impact nor one off the arc, and never into the arc still followed.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "detect/flight_samples.h"
#include "detect_sim.h"
#include "detector_parts.h"

namespace bouncefit {
namespace {

using testing::StoppedDrop;

TEST(FlightSamples, AClosedArcTakesBackTheSamplesOnItButNotThoseAtItsImpacts) {
  StoppedDrop drop;  // ping-pong, 1 m, 120 fps, 300 px/m
  drop.Stop(drop.clip.truth.impact_times_s[2] + 0.05);
  ASSERT_TRUE(drop.host.scene.calibrated());
  ASSERT_EQ(drop.arcs.arcs().size(), 4u);

  // The first rebound loses every other sample; one of them is seen off the arc.
  DetectorArc& rebound = drop.arcs.arcs()[1];
  std::vector<DetectorSample> kept, lost;
  for (size_t i = 0; i < rebound.samples.size(); ++i) (i % 2 ? lost : kept).push_back(rebound.samples[i]);
  rebound.samples = kept;
  const double stray_t = lost[lost.size() / 2].t;
  FlightSamples seen(drop.host.scene);
  for (DetectorSample s : drop.host.samples) {
    if (s.t <= drop.clip.truth.release_time_s) continue;
    if (s.t == stray_t) s.y -= 20;
    seen.Saw(s);
  }
  const size_t current = drop.arcs.arcs().back().samples.size();
  ASSERT_TRUE(seen.ReadmitInto(drop.arcs));
  EXPECT_TRUE(std::is_sorted(rebound.samples.begin(), rebound.samples.end(),
                             [](const DetectorSample& a, const DetectorSample& b) { return a.t < b.t; }));
  const double frame = drop.host.scene.frame_dt();
  const auto& impacts = drop.host.scene.calibration().impacts;
  for (const DetectorSample& q : lost) {
    const bool back = std::any_of(rebound.samples.begin(), rebound.samples.end(),
                                  [&](const DetectorSample& a) { return a.t == q.t; });
    const bool at_impact = q.t < impacts[0].t + frame || q.t > impacts[1].t - frame;
    EXPECT_EQ(back, !at_impact && q.t != stray_t) << "t " << q.t;
  }
  // The arc still followed is the follower's alone.
  EXPECT_EQ(drop.arcs.arcs().back().samples.size(), current);
  // Nothing more to take.
  EXPECT_FALSE(seen.ReadmitInto(drop.arcs));
}

TEST(FlightSamples, NothingIsTakenBackBeforeAnImpact) {
  StoppedDrop drop;
  drop.Stop(drop.clip.truth.impact_times_s[0]);
  ASSERT_EQ(drop.arcs.arcs().size(), 1u);
  FlightSamples seen(drop.host.scene);
  for (const auto& s : drop.host.samples) seen.Saw(s);
  drop.arcs.arcs()[0].samples.resize(drop.arcs.arcs()[0].samples.size() / 2);
  EXPECT_FALSE(seen.ReadmitInto(drop.arcs));
  seen.RescaleTime(2);
  EXPECT_EQ(seen.seen().back().t, 2 * drop.host.samples.back().t);
  seen.Clear();
  EXPECT_TRUE(seen.seen().empty());
}

}  // namespace
}  // namespace bouncefit
