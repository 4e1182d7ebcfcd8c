// The final fit on a point-mass drop with known truth: its budget holds everything, its
// searches recover the truth from the preset and the next one starts there, the Jacobian
// gives the uncertainties, the free-running check and the restitution points follow; a
// cancelled fit keeps its start. The soft ball's restitution law reads its own budget.
#include <gtest/gtest.h>

#include <atomic>

#include "fit/final_fit.h"
#include "fit/fit_models.h"
#include "fit/update_report.h"
#include "model/ball_preset.h"
#include "model/point_mass_model.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

// A session's parts without the session: the softball preset fitted to a truth whose e is 0.50.
struct Final {
  Final() : model(*FindBallPreset("softball")) {
    config.max_evaluations_final = 150;
    config.final_starts = 1;  // a smooth model: one search gets there
    config.ensemble_members = 2;
    BallPreset truth = *FindBallPreset("softball");
    truth.restitution = 0.50;
    const auto h = testing::DropHeights(truth, 1.2, 5);
    for (int b = 0; b <= 5; ++b) drop.Add(b, {h[b], 0.001});
    for (const auto& s : model.Coefficients()) start[s.name] = s.default_value;
  }
  FinalFit Make() const {
    return FinalFit(model, nullptr, config, drop, kept, problems, start,
                    LiveOrder(FreeCoefficients(model, config), config));
  }
  PointMassModel model;
  FitSessionConfig config;
  RecordedDrop drop{0.01, 0.002};
  std::vector<KeptDrop> kept;
  DropProblems problems{model, config, drop, kept};
  CoefficientValues start;
};

TEST(FinalFit, RecoversTheTruthWithinItsBudgetAndStartsTheNextThere) {
  const Final f;
  FinalFit fit = f.Make();
  EXPECT_EQ(fit.Budget(), 150);  // no restitution law: the configured budget
  std::atomic<int> simulations{0};
  const FinalSearchResult s = fit.Search(nullptr, &simulations);
  EXPECT_FALSE(s.result.cancelled);
  EXPECT_NEAR(s.result.values.at("restitution"), 0.50, 0.02);
  EXPECT_EQ(s.problem.free.size(), 3u);  // every free coefficient
  ASSERT_EQ(s.jacobian.size(), 3u);      // bounces above a centimetre x coefficients, at the answer
  EXPECT_EQ(s.jacobian[0].size(), 3u);
  EXPECT_GT(s.jacobian_evaluations, 0);
  EXPECT_TRUE(s.held.empty());
  UpdateContext c;
  c.reported = FreeCoefficients(f.model, f.config);
  c.measurement_sigma_m = f.drop.MeasurementSigma();
  FitUpdate u = ReportUpdate(c, s.problem, s.result, true, s.jacobian, s.jacobian_evaluations, 0, f.model);
  fit.Check(s, nullptr, &simulations, &u);
  EXPECT_LE(u.evaluations, fit.Budget());
  EXPECT_EQ(simulations.load(), u.evaluations);
  // The free-running drop at the answer, and its ensemble.
  ASSERT_EQ(u.simulated_m.size(), 3u);
  EXPECT_LT(u.residual_m, 0.001 * 1.2);
  EXPECT_EQ(u.free_run_mean_m.size(), 3u);
  EXPECT_LT(u.free_run_residual_m, 0.002);
  // The bounces' own restitution: the three rebounds of one drop.
  EXPECT_EQ(u.restitution_points.size(), 3u);
  EXPECT_TRUE(u.restitution.drops_agree);
  // The next final fit starts at the answer: its searches have less to do.
  const FinalSearchResult again = fit.Search(nullptr, &simulations);
  EXPECT_NEAR(again.result.values.at("restitution"), s.result.values.at("restitution"), 0.005);
}

TEST(FinalFit, ACancelledFitKeepsItsStart) {
  const Final f;
  FinalFit fit = f.Make();
  std::atomic<int> simulations{0};
  CancelToken cancel;
  cancel.Cancel();
  const FinalSearchResult s = fit.Search(&cancel, &simulations);
  EXPECT_TRUE(s.result.cancelled);
  EXPECT_EQ(s.jacobian_evaluations, 0);
  // Not cancelled, it searches from the preset as before.
  const FinalSearchResult r = fit.Search(nullptr, &simulations);
  EXPECT_NEAR(r.result.values.at("restitution"), 0.50, 0.02);
}

TEST(FinalFit, TheSoftBallsRestitutionLawBudgetsItsTwoStages) {
  FitSetup setup;
  setup.ball = ResolveBallPreset("tennis");
  const FitModels m = MakeFitModels(setup);
  RecordedDrop drop(0.01, 0.002);
  const std::vector<KeptDrop> kept;
  const DropProblems problems(*m.model, m.session, drop, kept);
  const FinalFit law(*m.model, m.quick.get(), m.session, drop, kept, problems, {}, {});
  const FinalFit boost(*m.model, nullptr, m.session, drop, kept, problems, {}, {});
  EXPECT_EQ(boost.Budget(), m.session.max_evaluations_final);  // no quick model: no law
  EXPECT_LT(law.Budget(), m.session.max_evaluations_final);    // ~60 simulations and the checks
  EXPECT_GT(law.Budget(), 2 * static_cast<int>(FreeCoefficients(*m.model, m.session).size()) + 2);
}

}  // namespace
}  // namespace bouncefit
