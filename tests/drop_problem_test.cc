// The fit session's problems on a point-mass drop with known truth: the recorded heights and
// flights, the simulation's length and bounces, the kept drops in the final fits only, the
// first fall on the heights' clock, and the safe drops; run at the truth, the heights match.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fit/drop_problem.h"
#include "model/ball_preset.h"
#include "model/point_mass_model.h"
#include "tests/point_mass_truth.h"

namespace bouncefit {
namespace {

// The truth's apexes 0..last recorded, impacts and apex times on its clock times `clock`.
RecordedDrop Recorded(const PointMassDropResult& t, int last, double clock = 1) {
  RecordedDrop d(0.01, 0.002);
  for (int b = 0; b <= last; ++b)
    d.Add(b, {t.apex_heights_m[b], 0.001, b > 0 ? clock * t.impact_times_s[b - 1] : std::nan(""),
              clock * t.apex_times_s[b]});
  return d;
}

CoefficientValues Defaults(const BallModel& model) {
  CoefficientValues v;
  for (const auto& s : model.Coefficients()) v[s.name] = s.default_value;
  return v;
}

TEST(DropProblems, TheTruthsCoefficientsMatchItsHeights) {
  BallPreset truth = *FindBallPreset("tennis");
  truth.restitution = 0.8;
  const PointMassDropResult t = testing::PointMassTruth(truth, 1.2);
  const PointMassModel model(truth);
  FitSessionConfig config;
  const RecordedDrop drop = Recorded(t, 5);
  const std::vector<KeptDrop> kept;
  const DropProblems problems(model, config, drop, kept);
  const FitProblem p = problems.Make(model.Coefficients(), Defaults(model));
  ASSERT_EQ(p.recorded_m.size(), 5u);
  EXPECT_EQ(p.recorded_m, drop.fitted_heights());
  EXPECT_DOUBLE_EQ(p.simulation.drop_height_m, 1.2);
  EXPECT_EQ(p.simulation.max_bounces, 5);  // never past the last recorded bounce
  EXPECT_DOUBLE_EQ(p.flight_weight_mps, config.flight_weight_mps);  // the restitution law's timing
  EXPECT_NEAR(p.start_fall_s, t.impact_times_s[0] - t.release_time_s, 1e-12);
  // The live problem stops its simulations sooner.
  const FitProblem live = problems.Make(model.Coefficients(), Defaults(model), true);
  EXPECT_LT(live.simulation.duration_s, p.simulation.duration_s);
  EXPECT_GT(live.simulation.duration_s, t.apex_times_s[5] - t.release_time_s);
  SearchOptions o;
  o.threads = 1;
  FitObjective f(p, o);
  const Evaluation at_truth = f.Evaluate(f.ToUnit(Defaults(model)));
  ASSERT_TRUE(at_truth.ok) << at_truth.failure;
  for (size_t i = 0; i < p.recorded_m.size(); ++i)
    EXPECT_NEAR(at_truth.simulated_m[i], p.recorded_m[i], 1e-3 * p.recorded_m[i]) << i;
}

TEST(DropProblems, KeptDropsJoinTheFinalFitsOnly) {
  const BallPreset ball = *FindBallPreset("pingpong");
  const PointMassModel model(ball);
  FitSessionConfig config;
  const RecordedDrop first = Recorded(testing::PointMassTruth(ball, 1.0), 3);
  const std::vector<KeptDrop> kept{first.Keep()};
  const RecordedDrop drop = Recorded(testing::PointMassTruth(ball, 0.6), 2);
  const DropProblems problems(model, config, drop, kept);
  const FitProblem final_fit = problems.Make(model.Coefficients(), Defaults(model));
  ASSERT_EQ(final_fit.recorded_m.size(), 5u);  // this drop's two, then the kept drop's three
  EXPECT_DOUBLE_EQ(final_fit.recorded_m[2], first.fitted_heights()[0]);
  ASSERT_EQ(final_fit.other_drops.size(), 1u);
  EXPECT_DOUBLE_EQ(final_fit.other_drops[0].drop_height_m, 1.0);
  EXPECT_EQ(final_fit.other_drops[0].bounces, 3);
  EXPECT_EQ(final_fit.recorded_flight_s.size(), 5u);
  const FitProblem live = problems.Make(model.Coefficients(), Defaults(model), true);
  EXPECT_EQ(live.recorded_m.size(), 2u);
  EXPECT_TRUE(live.other_drops.empty());
}

TEST(DropProblems, TheFirstFallIsReadOnTheHeightsClock) {
  const BallPreset ball = *FindBallPreset("tennis");
  const PointMassDropResult t = testing::PointMassTruth(ball, 1.0);
  const PointMassModel model(ball);
  FitSessionConfig config;
  const RecordedDrop drop = Recorded(t, 5, 4.0);  // stamps of a 4x slow-motion file
  const std::vector<KeptDrop> kept;
  const FitProblem p = DropProblems(model, config, drop, kept).Make(model.Coefficients(), Defaults(model));
  for (double f : p.recorded_flight_s) EXPECT_TRUE(std::isnan(f));
  // The fall divided by the flights' ratio to the heights' (about 4, drag aside).
  EXPECT_NEAR(p.start_fall_s, t.impact_times_s[0] - t.release_time_s, 0.1 * t.impact_times_s[0]);
  EXPECT_DOUBLE_EQ(p.start_fall_sigma_s, config.time_sigma_s / drop.flight_clock_ratio());
}

TEST(DropProblems, NoBounceIsNoProblemAndSafeDropsCostTheirRuns) {
  const BallPreset ball = *FindBallPreset("tennis");
  const PointMassModel model(ball);
  FitSessionConfig config;
  RecordedDrop drop(0.01, 0.002);
  drop.Add(0, {1.0, 0.001});
  const std::vector<KeptDrop> kept;
  const DropProblems problems(model, config, drop, kept);
  EXPECT_THROW(problems.Make(model.Coefficients(), Defaults(model)), std::logic_error);
  drop.Add(1, {0.6, 0.001});
  const FitProblem p = problems.Make(model.Coefficients(), Defaults(model));
  EXPECT_FALSE(problems.WithSafety(p).safety);  // not checked inside the search by default
  config.safe_search = true;
  const FitProblem safe = problems.WithSafety(p);
  ASSERT_TRUE(safe.safety);
  EXPECT_EQ(safe.safety_simulations, 3);  // 0.3 m, 2 m and the drop's own 1 m
  EXPECT_EQ(safe.safety(Defaults(model)), "");  // a point mass settles from any height
}

}  // namespace
}  // namespace bouncefit
