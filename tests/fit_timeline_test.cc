// fit/fit_timeline.h: a joint fit's heights split by drop, and the run's clock measured
// against the simulation from the apex times of a point-mass drop (its apexes stamped on a
// clip's clock: real time, a timeline slowed 4x, one off by the fit's timing).
#include "fit/fit_timeline.h"

#include <gtest/gtest.h>

#include "model/ball_preset.h"
#include "model/point_mass_model.h"

namespace bouncefit {
namespace {

// The ball dropped from 1 m, its apexes as a clip at `run_per_real` seconds of stamps per
// real second would time them, from a start apex at 2 s.
struct Stamped {
  FitDrop drop;
  std::vector<double> simulated_apex_s;
};
Stamped DropOnClock(double run_per_real) {
  const PointMassModel model(*FindBallPreset("tennis"));
  const SimulationResult r = SimulateFromStart(model, {}, 1.0, 6.0, 0.01);
  EXPECT_TRUE(r.ok) << r.failure;
  Stamped s;
  s.drop.start_t_s = 2.0;
  s.drop.start_height_m = 1.0;
  for (size_t i = 0; i < r.apex_times_s.size(); ++i) {
    s.drop.bounces.push_back(static_cast<int>(i) + 1);
    s.drop.apex_t_s.push_back(2.0 + run_per_real * r.apex_times_s[i]);
  }
  s.simulated_apex_s = r.apex_times_s;
  return s;
}

TEST(FitTimeline, RealTimeIsOneAndTheFitsTimingErrorIsNotAClock) {
  const Stamped real = DropOnClock(1.0);
  ASSERT_GE(real.simulated_apex_s.size(), 3u);
  EXPECT_EQ(RunSecondsPerRealSecond({real.drop}, {real.simulated_apex_s}), 1.0);
  // A fitted ball 8% slow (drag, a clip's clock a little off) is drawn on the clip's seconds.
  const Stamped off = DropOnClock(1.08);
  EXPECT_EQ(RunSecondsPerRealSecond({off.drop}, {off.simulated_apex_s}), 1.0);
}

TEST(FitTimeline, ASlowMotionFilesStampsAreItsSlowDown) {
  const Stamped slow = DropOnClock(4.0);
  EXPECT_EQ(RunSecondsPerRealSecond({slow.drop}, {slow.simulated_apex_s}), 4.0);
  // Within 5% of a whole slow-down: that slow-down; between two, as measured.
  const Stamped near = DropOnClock(3.9);
  EXPECT_EQ(RunSecondsPerRealSecond({near.drop}, {near.simulated_apex_s}), 4.0);
  const Stamped between = DropOnClock(2.5);
  EXPECT_NEAR(RunSecondsPerRealSecond({between.drop}, {between.simulated_apex_s}), 2.5, 1e-9);
  // No apex time: nothing to measure, real time.
  FitDrop untimed = slow.drop;
  for (double& t : untimed.apex_t_s) t = std::nan("");
  EXPECT_EQ(RunSecondsPerRealSecond({untimed}, {slow.simulated_apex_s}), 1.0);
}

TEST(FitTimeline, AJointFitsHeightsSplitByDrop) {
  // The order FitSession writes: this drop's heights, then each other drop's.
  FitUpdate u;
  u.drop_height_m = 0.8;
  u.recorded_m = {0.5, 0.3, 0.6, 0.4, 0.25};
  u.simulated_m = u.recorded_m;
  u.other_drop_heights_m = {1.0};
  u.other_drop_bounces = {3};
  const auto slices = FitDropSlices(u);
  ASSERT_EQ(slices.size(), 2u);
  EXPECT_EQ(slices[0].first, 0u);
  EXPECT_EQ(slices[0].count, 2u);
  EXPECT_EQ(slices[0].start_height_m, 0.8);
  EXPECT_EQ(slices[1].first, 2u);
  EXPECT_EQ(slices[1].count, 3u);
  EXPECT_EQ(slices[1].start_height_m, 1.0);
  // One drop: all of it.
  u.other_drop_heights_m.clear();
  u.other_drop_bounces.clear();
  ASSERT_EQ(FitDropSlices(u).size(), 1u);
  EXPECT_EQ(FitDropSlices(u)[0].count, 5u);
}

}  // namespace
}  // namespace bouncefit
