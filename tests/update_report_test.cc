// A search's answer as a FitUpdate, on a point-mass drop with known truth: the fitted
// restitution with an uncertainty that covers the truth, the covariance of the identifiable
// ones, the coefficients not searched reported at their values, the flights' clock warning;
// and where coefficients hold (time step, iterations).
#include <gtest/gtest.h>

#include <cmath>

#include "fit/least_squares_search.h"
#include "fit/update_report.h"
#include "model/ball_preset.h"
#include "model/point_mass_model.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

struct Fitted {
  FitProblem problem;
  SearchResult result;
};

// The restitution fitted to a truth drop whose e is 0.55, from the preset's.
Fitted FitRestitution(const PointMassModel& model) {
  BallPreset truth = *FindBallPreset("softball");
  truth.restitution = 0.55;
  const auto h = testing::DropHeights(truth, 1.2, 5);
  Fitted f;
  f.problem.model = &model;
  f.problem.free = {model.Coefficients()[0]};  // restitution
  f.problem.recorded_m.assign(h.begin() + 1, h.end());
  f.problem.simulation.drop_height_m = h[0];
  f.problem.simulation.duration_s = 6;
  f.problem.simulation.min_bounce_height_m = 0.005;
  SearchOptions o;
  o.threads = 1;
  f.result = LeastSquaresSearch(f.problem, {}, o);
  return f;
}

TEST(UpdateReport, TheFittedCoefficientCarriesItsUncertaintyTheOthersTheirValues) {
  const PointMassModel model(*FindBallPreset("softball"));
  const Fitted f = FitRestitution(model);
  ASSERT_FALSE(f.result.jacobian.empty());
  UpdateContext c;
  c.utime = 42;
  c.sequence = 3;
  c.start_bounce = 0;
  c.after_bounce = 5;
  c.drop_height_m = 1.2;
  c.measurement_sigma_m = 0.002;
  c.reported = model.Coefficients();
  const FitUpdate u = ReportUpdate(c, f.problem, f.result, true, f.result.jacobian, 4, 0.5, model);
  EXPECT_EQ(u.utime, 42);
  EXPECT_EQ(u.sequence, 3);
  EXPECT_EQ(u.after_bounce, 5);
  EXPECT_TRUE(u.final);
  EXPECT_EQ(u.model, "point-mass");
  EXPECT_EQ(u.evaluations, f.result.evaluations + 4);
  EXPECT_LT(u.residual_m, 0.002);
  EXPECT_TRUE(u.warning.empty()) << u.warning;
  ASSERT_EQ(u.coefficients.size(), 3u);  // every one reported, the searched one first
  const CoefficientEstimate& e = u.coefficients[0];
  EXPECT_EQ(e.name, "restitution");
  EXPECT_TRUE(e.identifiable);
  EXPECT_NEAR(e.value, 0.55, 0.01);
  EXPECT_GT(e.sigma, 0);
  EXPECT_LT(e.sigma, 0.05);
  ASSERT_EQ(u.covariance_names, std::vector<std::string>{"restitution"});
  EXPECT_GT(u.covariance[0][0], 0);
  // Not searched: the preset's value, no uncertainty.
  EXPECT_EQ(u.coefficients[1].name, "restitution_per_mps");
  EXPECT_DOUBLE_EQ(u.coefficients[1].value, FindBallPreset("softball")->restitution_per_mps);
  EXPECT_TRUE(std::isnan(u.coefficients[1].sigma));
  EXPECT_EQ(u.coefficients[1].note, "held fixed in this update");
  // Without a Jacobian nothing has an uncertainty.
  const FitUpdate none = ReportUpdate(c, f.problem, f.result, false, {}, 0, 0.5, model);
  EXPECT_EQ(none.coefficients[0].note, "no sensitivity computed");
  EXPECT_TRUE(none.covariance.empty());
}

TEST(UpdateReport, FlightsOnAnotherClockAreSaidAndTheStepIsTheContexts) {
  const PointMassModel model(*FindBallPreset("softball"));
  const Fitted f = FitRestitution(model);
  UpdateContext c;
  c.flight_clock_ratio = 4.0;
  c.time_step_s = 1.0 / 960;
  c.iterations = 4;
  c.reported = model.Coefficients();
  const FitUpdate u = ReportUpdate(c, f.problem, f.result, false, f.result.jacobian, 0, 0, model);
  EXPECT_NE(u.warning.find("the flight times between impacts are 4x what the heights give"), std::string::npos)
      << u.warning;
  EXPECT_DOUBLE_EQ(u.time_step_s, 1.0 / 960);  // the point mass's values do not say
  EXPECT_EQ(u.iterations, 4);
}

TEST(UpdateReport, WhereCoefficientsHoldIsReadFromTheirNames) {
  EXPECT_DOUBLE_EQ(TimeStepOf({{"time_step_s", 0.002}, {"pressure", 2}}), 0.002);
  EXPECT_EQ(IterationsOf({{"solver_iterations", 7.6}}), 8);
  const PointMassModel model(*FindBallPreset("tennis"));
  CoefficientValues defaults;
  for (const auto& s : model.Coefficients()) defaults[s.name] = s.default_value;
  EXPECT_EQ(TimeStepOf(defaults), 0);
  EXPECT_EQ(IterationsOf(defaults), 0);
}

}  // namespace
}  // namespace bouncefit
