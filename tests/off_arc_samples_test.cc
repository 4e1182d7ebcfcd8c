// The samples an arc turned away: counted as misses in a row until the arc takes them or a
// new one begins, merged in time order, their times rescaled; a far detection that comes
// back to where the last one was is something standing still.
#include <gtest/gtest.h>

#include "detect/off_arc_samples.h"

namespace bouncefit {
namespace {

DetectorSample At(double t, double x = 100, double y = 200, double r = 10) {
  return {t, x, y, r, static_cast<int64_t>(t * 1e6)};
}

TEST(OffArcSamples, CountsMissesInARowUntilCleared) {
  OffArcSamples off;
  off.TurnAway(At(0.10), false);
  off.TurnAway(At(0.11), true);
  off.TurnAway(At(0.12), true);
  EXPECT_EQ(off.misses(), 3);
  ASSERT_EQ(off.rising().size(), 2u);
  EXPECT_EQ(off.rising().front().t, 0.11);
  off.Clear();
  EXPECT_EQ(off.misses(), 0);
  EXPECT_TRUE(off.rising().empty());
  EXPECT_TRUE(off.InTimeOrder().empty());
}

TEST(OffArcSamples, RisingAndOtherSamplesMergeInTimeOrder) {
  OffArcSamples off;
  off.TurnAway(At(0.30), true);
  off.TurnAway(At(0.10), false);
  off.TurnAway(At(0.40), false);
  off.TurnAway(At(0.20), true);
  const auto all = off.InTimeOrder();
  ASSERT_EQ(all.size(), 4u);
  for (size_t i = 0; i < all.size(); ++i) EXPECT_DOUBLE_EQ(all[i].t, 0.1 * static_cast<double>(i + 1));
  // The latest of the arc's last sample and the newest of each kind pending.
  EXPECT_EQ(off.LastT(0.05), 0.40);
  EXPECT_EQ(off.LastT(0.50), 0.50);
  off.RescaleTime(2);
  EXPECT_DOUBLE_EQ(off.InTimeOrder().back().t, 0.80);
  EXPECT_DOUBLE_EQ(off.rising().front().t, 0.60);
}

TEST(OffArcSamples, AFarDetectionWhereTheLastOneWasIsStandingStill) {
  OffArcSamples off;
  const double gate = 2;
  EXPECT_FALSE(off.FarAgain(At(0.1, 500, 50), true, gate));  // the first: nothing to compare
  EXPECT_TRUE(off.FarAgain(At(0.2, 505, 52), true, gate));   // within its radius and the gate
  EXPECT_FALSE(off.FarAgain(At(0.3, 560, 52), true, gate));  // it moved: maybe the ball
  EXPECT_TRUE(off.FarAgain(At(0.4, 561, 52), true, gate));
  // A near sample between two far ones: the second is compared with nothing.
  EXPECT_FALSE(off.FarAgain(At(0.5, 100, 200), false, gate));
  EXPECT_FALSE(off.FarAgain(At(0.6, 561, 52), true, gate));
  // The drop ended: no far detection remembered.
  off.Reset();
  EXPECT_FALSE(off.FarAgain(At(0.7, 561, 52), true, gate));
}

}  // namespace
}  // namespace bouncefit
