// The fit with the Bullet soft-body model (real Bullet runs): the final fit matches the
// heights of each of the four ball presets to 1% of the drop height.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <thread>

#include "fit/drop_ensemble.h"
#include "fit/fit_models.h"
#include "fit/fit_session.h"
#include "fit/fit_worker.h"
#include "model/ball_preset.h"
#include "model/model_by_name.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"
#include "tests/point_mass_truth.h"

namespace bouncefit {
namespace {

class FinalFit : public ::testing::TestWithParam<const char*> {};

TEST_P(FinalFit, RmsWithinOnePercentOfTheDropOverAllBouncesAboveOneCentimetre) {
  const BallPreset ball = ResolveBallPreset(GetParam());
  const double drop = 1.0;
  const auto truth = testing::PointMassTruth(ball, drop);
  auto model = MakeBallModel("bullet-softbody", ball);
  PointMassModel quick(ball);
  FitSessionConfig cfg;
  cfg.impact = "boost";  // the whole-coefficient search, which screens what has no effect
  ConfigureSessionForModel(*model, ball, &cfg);
  // The first of the default's three starts alone, with the budget each of them has
  // ((945 - 45) / 3 = 300 searched simulations): the default keeps the best of its starts,
  // each deterministic on its own and this one among them, so its answer is at least as close
  // as this one. A third of the simulations, the same 1% to meet (pingpong 7.74 mm here,
  // 6.69 mm as the best of three; wiffle, softball and airball: the same answer).
  cfg.final_starts = 1;
  cfg.max_evaluations_final = 345;
  FitSession session(*model, &quick, cfg);
  session.AddPeak({0, 0, drop, 0.001, 0});
  for (size_t i = 1; i < truth.apex_heights_m.size(); ++i)
    session.AddPeak({0, static_cast<int>(i), truth.apex_heights_m[i], 0.001, 0});
  const auto r = session.FittedHeights();
  ASSERT_GE(r.size(), 2u);
  for (double h : r) EXPECT_GE(h, 0.01);
  const FitUpdate u = session.FinalUpdate();
  EXPECT_TRUE(u.final);
  EXPECT_EQ(u.model, "bullet-softbody");
  EXPECT_EQ(u.recorded_m.size(), r.size());
  EXPECT_GT(u.time_step_s, 0);
  EXPECT_GT(u.iterations, 0);
  std::printf("%s: %zu bounces, RMS %.2f mm (%.2f%% of the drop), %d simulations, %.1f s\n",
              ball.name.c_str(), r.size(), u.residual_m * 1000, 100 * u.residual_m / drop,
              u.evaluations, u.wall_time_s);
  EXPECT_LE(u.residual_m, 0.01 * drop);
  // Bullet 3.24's solver never reads a material's m_kAST and m_kVST (docs/MODEL.md): the fit
  // finds out and says so.
  for (const char* name : {"angular_stiffness", "volume_stiffness"}) {
    bool found = false;
    for (const auto& n : u.no_effect) found = found || n == name;
    EXPECT_TRUE(found) << name << " not reported as having no effect";
  }
}

// Safety: the stored airball table goes through the floor dropped from 0.3 m. A
// final fit started from it rejects it (and every other candidate that diverges) inside the
// search; the answer runs to rest from 0.3 m and from 2 m.
TEST(FinalFitSafety, UnsafeCandidatesAreRejectedInsideTheSearch) {
  const BallPreset ball = ResolveBallPreset("airball");
  const double drop = 1.0;
  const auto truth = testing::PointMassTruth(ball, drop);
  auto model = MakeBallModel("bullet-softbody", ball);
  FitSessionConfig cfg;
  cfg.impact = "boost";  // the stored airball table (the boost's) is the unsafe start
  ConfigureSessionForModel(*model, ball, &cfg);
  ASSERT_NE(UnsafeDrop(*model, cfg.start, {0.3}, 2), "") << "the start is no longer unsafe";
  cfg.final_starts = 1;
  cfg.max_evaluations_final = 120;
  cfg.ensemble_members = 2;
  FitSession session(*model, nullptr, cfg);
  session.AddPeak({0, 0, drop, 0.001, 0});
  for (size_t i = 1; i < truth.apex_heights_m.size(); ++i)
    session.AddPeak({0, static_cast<int>(i), truth.apex_heights_m[i], 0.001, 0});
  const FitUpdate u = session.FinalUpdate();
  std::printf("airball from its unsafe table: %d candidates checked, %d rejected, RMS %.2f mm, "
              "%d simulations, %.1f s\n",
              u.safety_checks, u.rejected_unsafe, u.residual_m * 1000, u.evaluations,
              u.wall_time_s);
  EXPECT_GE(u.rejected_unsafe, 1);
  EXPECT_GT(u.safety_checks, u.rejected_unsafe);
  EXPECT_LE(u.evaluations, cfg.max_evaluations_final);
  EXPECT_EQ(UnsafeDrop(*model, u.values, {0.3, 2.0, drop}, 2), "");
  EXPECT_EQ(u.warning.find("the fitted ball diverges"), std::string::npos) << u.warning;
}

INSTANTIATE_TEST_SUITE_P(Presets, FinalFit,
                         ::testing::Values("pingpong", "wiffle", "softball", "airball"));

// A 1 m ping-pong drop, peaks emitted 50 ms after their apex (the detector's latency) on
// the wall clock: each of the first five bounces' update is out before the next apex.
}  // namespace
}  // namespace bouncefit
