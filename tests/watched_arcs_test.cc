// Heard arcs the picture watched and did not see, on a real point-mass drop (impact times
// from the model): past the last seen impact, an arc heard at both ends is one the picture
// followed the ball through unless the tracker lost it there; arcs with a seen end, arcs
// before the last seen impact and arcs past the stream's frames never are.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "detect/impact_fusion.h"
#include "detect/watched_arcs.h"
#include "model/ball_preset.h"
#include "model/point_mass_drop.h"

namespace bouncefit {
namespace {

PointMassDropResult Drop() {
  PointMassDropConfig c;
  c.ball = ResolveBallPreset("tennis");
  c.drop_height_m = 1.0;
  c.hold_s = 0.5;
  c.end_time_s = 8;
  c.min_apex_height_m = 0.001;
  return SimulatePointMassDrop(c);
}

ImpactFusionConfig Config() {
  const BallPreset b = ResolveBallPreset("tennis");
  ImpactFusionConfig c;
  c.drag_per_m = 0.5 * 1.2 * b.drag_coefficient * std::numbers::pi * b.diameter_m * b.diameter_m / 4 / b.mass_kg;
  return c;
}

std::vector<AudioImpact> Heard(const std::vector<double>& times) {
  std::vector<AudioImpact> out;
  for (double t : times) out.push_back({t + 0.03, 0.1, 30, 1});
  return out;
}

// Frames at 30 fps from 0 to end_s; the ball not found in (lost_from_s, lost_to_s).
PictureCoverage Frames(double end_s, double lost_from_s = -1, double lost_to_s = -1) {
  PictureCoverage p;
  for (double t = 0; t <= end_s; t += 1 / 30.0) p.AddFrame(t, !(t > lost_from_s && t < lost_to_s));
  return p;
}

// The drop's impacts heard, its first five seen: the heard train goes on after them.
FusionResult FiveSeen(const PointMassDropResult& r) {
  const std::vector<double> seen(r.impact_times_s.begin(), r.impact_times_s.begin() + 5);
  return FuseImpacts(Heard(r.impact_times_s), seen, r.impact_times_s.back() + 1, Config());
}

TEST(WatchedArcs, PastTheLastSeenImpactTheArcsHeardAtBothEndsTheBallFollowedThrough) {
  const PointMassDropResult r = Drop();
  ASSERT_GE(r.impact_times_s.size(), 10u);
  const FusionResult f = FiveSeen(r);
  ASSERT_TRUE(f.sound_used) << f.verdict;
  ASSERT_GE(f.flights.size(), 8u);
  const std::vector<bool> unseen = ArcsWatchedUnseen(f, Frames(r.impact_times_s.back() + 1));
  ASSERT_EQ(unseen.size(), f.flights.size());
  for (size_t k = 0; k < f.flights.size(); ++k) {
    // Flight 4 begins at the last seen impact: the picture's own last arc, seen to begin.
    EXPECT_EQ(unseen[k], f.flights[k].from >= 5) << "flight from impact " << f.flights[k].from;
  }
}

TEST(WatchedArcs, AnArcWhereTheTrackerLostTheBallIsTheSoundsAlone) {
  const PointMassDropResult r = Drop();
  const FusionResult f = FiveSeen(r);
  ASSERT_TRUE(f.sound_used) << f.verdict;
  ASSERT_GE(f.flights.size(), 8u);
  // A frame or two without the ball at flight 6's apex; the frames end inside flight 8.
  const double apex = 0.5 * (r.impact_times_s[6] + r.impact_times_s[7]);
  const std::vector<bool> unseen =
      ArcsWatchedUnseen(f, Frames(r.impact_times_s[8] + 0.05, apex - 0.03, apex + 0.03));
  for (size_t k = 0; k < f.flights.size(); ++k) {
    const int from = f.flights[k].from;
    EXPECT_EQ(unseen[k], from == 5 || from == 7) << "flight from impact " << from;
  }
}

TEST(WatchedArcs, ImpactsThePictureMissedBetweenSeenOnesAreNotPastIt) {
  const PointMassDropResult r = Drop();
  ASSERT_GE(r.impact_times_s.size(), 8u);
  // Seen: impacts 0-2 and 5-7; 3 and 4 fill the gap from the sound.
  std::vector<double> seen;
  for (int i : {0, 1, 2, 5, 6, 7}) seen.push_back(r.impact_times_s[i]);
  const FusionResult f = FuseImpacts(Heard(r.impact_times_s), seen, r.impact_times_s.back() + 1, Config());
  ASSERT_TRUE(f.sound_used) << f.verdict;
  bool gap_heard = false;
  const std::vector<bool> unseen = ArcsWatchedUnseen(f, Frames(r.impact_times_s.back() + 1));
  for (size_t k = 0; k < f.flights.size(); ++k) {
    const int from = f.flights[k].from;
    if (from == 3) gap_heard = f.flights[k].heard_only;
    EXPECT_EQ(unseen[k], from >= 8) << "flight from impact " << from;
  }
  EXPECT_TRUE(gap_heard) << "the gap's arc is heard only";
}

}  // namespace
}  // namespace bouncefit
