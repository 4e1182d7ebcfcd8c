// Following a rendered drop in flight with the follower and the least host
// (tests/detector_parts.h): every impact is confirmed within a few frames of the truth, a
// stray detection off the arc is dropped, the drop ends at rest.
#include <gtest/gtest.h>

#include <cmath>

#include "detect_sim.h"
#include "detector_parts.h"

namespace bouncefit {
namespace {

TEST(FlightFollower, ConfirmsEveryImpactWithinAFewFramesOfTheTruth) {
  testing::SimOptions o;  // ping-pong, 1 m, 120 fps, 300 px/m
  const auto clip = testing::MakeSimClip(o);
  const auto truth = testing::TruthOf(clip);
  testing::PartsHost host;
  host.Run(clip.obs);
  ASSERT_EQ(host.starts.size(), 1u);
  // Impacts whose rebound rises above 1 cm: an impact is confirmed by the second sample off
  // the falling arc, so a frame or two after it.
  size_t tall = 0;
  while (tall + 1 < truth.apex_h_m.size() && truth.apex_h_m[tall + 1] > 0.01) ++tall;
  ASSERT_GE(tall, 5u);
  ASSERT_GE(host.impact_confirmed_t.size(), tall);
  for (size_t i = 0; i < tall; ++i) {
    const double late = (host.impact_confirmed_t[i] - truth.impact_t_s[i]) * o.fps;
    EXPECT_GT(late, 0) << "impact " << i + 1;
    EXPECT_LT(late, 4) << "impact " << i + 1;
  }
  ASSERT_EQ(host.end_reasons.size(), 1u);
  EXPECT_EQ(host.end_reasons[0], "rest");
}

TEST(FlightFollower, AStrayDetectionOffTheArcIsNotAnImpact) {
  testing::SimOptions o;
  auto clip = testing::MakeSimClip(o);
  testing::PartsHost clean;
  clean.Run(clip.obs);
  // One frame in the first fall, 40 px off to the side.
  const size_t i = static_cast<size_t>((o.hold_s + 0.25) * o.fps);
  clip.obs[i].cx += 40;
  testing::PartsHost stray;
  stray.Run(clip.obs);
  EXPECT_EQ(stray.impact_confirmed_t.size(), clean.impact_confirmed_t.size());
  ASSERT_FALSE(stray.follower.arcs().empty() && stray.end_reasons.empty());
  EXPECT_EQ(stray.end_reasons, clean.end_reasons);
}

}  // namespace
}  // namespace bouncefit
