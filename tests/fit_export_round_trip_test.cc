// A fit's exported coefficients.json, run again: `simulate` (and `predict`) at the fitted
// drop print exactly the heights the fit reported. A real, small soft-body fit.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "fit/fit_export.h"
#include "fit/fit_models.h"
#include "fit/fit_session.h"
#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/soft_ball_model.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

// A final fit of three bounces with a handful of simulations (its answer need not be good:
// what it reports must be what its exported file gives).
FitUpdate SmallFinalFit(const BallPreset& ball, const SoftBallModel& model) {
  FitSessionConfig cfg;
  cfg.max_evaluations_final = 8;
  cfg.final_starts = 1;
  cfg.threads = 2;
  ConfigureSessionForModel(model, ball, &cfg);
  // A fixed coefficient away from its default: the export must carry it too.
  cfg.start["floor_friction"] = 0.6;
  FitSession s(model, nullptr, cfg);
  const double heights[] = {1.0003, 0.652, 0.46, 0.34};
  for (int i = 0; i < 4; ++i) s.AddPeak({0, i, heights[i], 0.002, 0});
  return s.FinalUpdate();
}

TEST(FitExportReplay, SimulateOnTheExportedFileGivesTheFitsHeights) {
  const BallPreset ball = *FindBallPreset("pingpong");
  const SoftBallModel model(ball);
  const FitUpdate u = SmallFinalFit(ball, model);
  ASSERT_EQ(u.simulated_m.size(), 3u);
  ASSERT_GT(u.simulated_m[2], 0);
  const auto dir = testing::ScratchDir("export");
  WriteFitExports(dir, u, ball);

  // The table read back holds every value the model ran with, not only the fitted ones.
  const CoefficientTable t = LoadCoefficientTable(dir / "coefficients.json");
  EXPECT_EQ(t.values, u.values);
  EXPECT_EQ(t.values.at("floor_friction"), 0.6);
  EXPECT_EQ(t.model, "bullet-softbody");
  EXPECT_EQ(t.ball, "pingpong");
  ASSERT_TRUE(t.drop_height_m.has_value());
  EXPECT_EQ(*t.drop_height_m, u.drop_height_m);

  std::string out;
  const int rc = testing::RunCommand(testing::BouncefitExe() +
                                         " simulate --ball pingpong --no-trajectory --json --coeffs '" +
                                         (dir / "coefficients.json").string() + "' --drop " +
                                         fmt::format("{:.17g}", u.drop_height_m),
                                     &out);
  ASSERT_EQ(rc, 0) << out;
  const auto j = nlohmann::json::parse(out);
  const auto heights = j["bounce_heights_m"].get<std::vector<double>>();
  ASSERT_GE(heights.size(), u.simulated_m.size()) << out;
  for (size_t i = 0; i < u.simulated_m.size(); ++i)
    EXPECT_EQ(heights[i], u.simulated_m[i]) << "bounce " << i + 1;

  // predict: its single run is simulate's; its ensemble (same members, same perturbations)
  // is the fit's free-running check.
  const int prc = testing::RunCommand(testing::BouncefitExe() + " predict --json --threads 2 --coeffs '" +
                                          (dir / "coefficients.json").string() + "' --drop " +
                                          fmt::format("{:.17g}", u.drop_height_m),
                                      &out);
  ASSERT_EQ(prc, 0) << out;
  const auto p = nlohmann::json::parse(out);
  const auto single = p["single_run_heights_m"].get<std::vector<double>>();
  const auto mean = p["bounce_heights_m"].get<std::vector<double>>();
  const auto sd = p["bounce_heights_sd_m"].get<std::vector<double>>();
  ASSERT_GE(single.size(), 3u) << out;
  ASSERT_GE(mean.size(), 3u) << out;
  ASSERT_EQ(u.free_run_mean_m.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(single[i], u.simulated_m[i]) << "bounce " << i + 1;
    EXPECT_EQ(mean[i], u.free_run_mean_m[i]) << "bounce " << i + 1;
    EXPECT_EQ(sd[i], u.free_run_sd_m[i]) << "bounce " << i + 1;
  }
  // The perturbations are real: the later bounces of the members differ.
  EXPECT_GT(sd[2], 0);
}

TEST(FitExportReplay, PredictRunsThePointMassModelToo) {
  const BallPreset ball = *FindBallPreset("tennis");
  const auto dir = testing::ScratchDir("point_mass");
  std::string out;
  const int rc = testing::RunCommand(testing::BouncefitExe() +
                                         " fit --heights 1.0,0.62,0.40,0.26 --ball tennis --model "
                                         "point-mass --final-only --max-evals 60 --export '" +
                                         dir.string() + "'",
                                     &out);
  ASSERT_EQ(rc, 0) << out;
  const int prc = testing::RunCommand(testing::BouncefitExe() + " predict --json --coeffs '" +
                                          (dir / "coefficients.json").string() + "' --drop 1.6",
                                      &out);
  ASSERT_EQ(prc, 0) << out;
  const auto p = nlohmann::json::parse(out);
  EXPECT_EQ(p["model"], "point-mass");
  const auto mean = p["bounce_heights_m"].get<std::vector<double>>();
  ASSERT_GE(mean.size(), 3u) << out;
  // Dropped from 1.6 m instead of 1.0 m, a ball with restitution ~0.79 rebounds higher.
  EXPECT_GT(mean[0], 0.85) << out;
  EXPECT_LT(mean[0], 1.1) << out;
  for (size_t i = 1; i < mean.size(); ++i) EXPECT_LT(mean[i], mean[i - 1]);
  // Bad input is a one-line error, not a crash.
  const int bad = testing::RunCommand(testing::BouncefitExe() + " predict --coeffs '" +
                                          (dir / "coefficients.json").string() + "' --drop -1",
                                      &out);
  EXPECT_EQ(bad, 2);  // a bad flag
  EXPECT_NE(out.find("bouncefit predict: error:"), std::string::npos) << out;
}

}  // namespace
}  // namespace bouncefit
