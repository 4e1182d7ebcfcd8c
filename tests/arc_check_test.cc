// The arc check on tracks of known motion: a ball's free fall is an arc whatever its horizontal
// speed; the same track from a blob that runs on out of the picture is none (an arm reaching in
// from the edge rises and slows as a tossed ball does), until the object shows whole.
#include <gtest/gtest.h>

#include "track/arc_check.h"

namespace bouncefit {
namespace {

constexpr double kFps = 26, kRadius = 40;
constexpr double kG = 6900;  // px/s^2: 9.81 m/s^2 at 700 px/m

// A toss: up at 800 px/s and sideways at `vx` px/s, from (1200, 500).
void AddToss(ArcCheck* arc, int from, int to, double vx, bool whole, bool* ballistic) {
  for (int i = from; i < to; ++i) {
    const double t = i / kFps;
    *ballistic = arc->Add(t, 1200 + vx * t, 500 - 800 * t + 0.5 * kG * t * t, kRadius, whole);
  }
}

TEST(ArcCheck, ATossIsAnArcWhateverItsHorizontalSpeed) {
  for (double vx : {0.0, -500.0, -1050.0}) {
    ArcCheck arc;
    bool ballistic = false;
    AddToss(&arc, 0, 6, vx, true, &ballistic);
    EXPECT_TRUE(ballistic) << vx;
  }
}

TEST(ArcCheck, ABlobRunningOutOfThePictureIsNoArcUntilItShowsWhole) {
  ArcCheck arc;
  bool ballistic = false;
  AddToss(&arc, 0, 10, -500, false, &ballistic);
  EXPECT_FALSE(ballistic);
  // Whole from here on: an arc once a stretch of whole samples is long enough.
  AddToss(&arc, 10, 12, -500, true, &ballistic);
  EXPECT_FALSE(ballistic);
  AddToss(&arc, 12, 16, -500, true, &ballistic);
  EXPECT_TRUE(ballistic);
}

}  // namespace
}  // namespace bouncefit
