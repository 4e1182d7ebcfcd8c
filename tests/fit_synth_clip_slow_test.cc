// The fit end to end as a user runs it: `bouncefit synth` renders a 1 m
// drop of each ball preset, `bouncefit run` tracks it, detects the apexes and fits the
// Bullet soft body after the last bounce; the final fit's RMS of (simulated - recorded)
// over every bounce above 1 cm is within 1% of the drop height. Real Bullet runs on the
// detector's heights (not the renderer's truth).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;

class FinalFitOnSynthClip : public ::testing::TestWithParam<const char*> {};

TEST_P(FinalFitOnSynthClip, RmsWithinOnePercentOfTheDrop) {
  const std::string ball = GetParam();
  const fs::path dir = testing::ScratchDir(ball);
  const fs::path clip = dir / (ball + ".avi");
  std::string log;
  // Long enough for every bounce above 1 cm (the ping-pong ball's tenth is at ~4.3 s).
  ASSERT_EQ(RunCommand(BouncefitExe() + " synth --quiet --ball " + ball +
                           " --drop-height 1 --duration 5 --out " + clip.string(),
                       &log),
            0)
      << log;
  const fs::path out = dir / "out";
  ASSERT_EQ(RunCommand(BouncefitExe() + " run " + clip.string() + " --ball " + ball +
                           " --speed 0 --lcm-url memq:// --out " + out.string(),
                       &log),
            0)
      << log;
  ASSERT_TRUE(fs::exists(out / "coefficients.json")) << "no final fit";
  const auto fit = nlohmann::json::parse(std::ifstream(out / "coefficients.json"));
  const auto summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  ASSERT_TRUE(fit.is_object()) << "no final fit in coefficients.json";
  // A final fit of more than a couple of seconds shows its progress meanwhile, never past
  // its budget ("final fit  N / B simulations").
  int most = -1, budget = 0;
  for (size_t at = log.find("final fit  "); at != std::string::npos;
       at = log.find("final fit  ", at + 1)) {
    most = std::max(most, std::atoi(log.c_str() + at + 11));
    const size_t slash = log.find(" / ", at);
    if (slash != std::string::npos) budget = std::atoi(log.c_str() + slash + 3);
  }
  if (fit["wall_time_s"].get<double>() > 2.5) {
    EXPECT_GT(most, 0) << "no progress of the final fit shown:\n" << log;
  }
  if (most >= 0) {
    EXPECT_LE(most, budget) << log;
  }
  EXPECT_EQ(fit["model"], "bullet-softbody");
  const double drop = fit["drop_height_m"].get<double>();
  const auto recorded = fit["recorded_m"].get<std::vector<double>>();
  const auto simulated = fit["simulated_m"].get<std::vector<double>>();
  ASSERT_GE(recorded.size(), 2u);
  ASSERT_EQ(recorded.size(), simulated.size());
  double sum = 0;
  for (size_t i = 0; i < recorded.size(); ++i) {
    EXPECT_GE(recorded[i], 0.01) << "bounce " << i + 1 << " is below the 1 cm the fit uses";
    sum += (simulated[i] - recorded[i]) * (simulated[i] - recorded[i]);
  }
  const double rms = std::sqrt(sum / static_cast<double>(recorded.size()));
  EXPECT_NEAR(rms, fit["residual_m"].get<double>(), 1e-9);
  // Every bounce above 1 cm that the detector saw is in the fit.
  int above = 0;
  for (const auto& p : summary["peaks"])
    if (p["sequence"] == 0 && p["bounce"].get<int>() > 0 && p["height_m"].get<double>() >= 0.01)
      ++above;
  EXPECT_EQ(static_cast<int>(recorded.size()), above);
  // One line per ball: the figures of docs/FIT.md "Final fit on rendered clips".
  std::printf("| %s | %.3f | %zu | %.2f | %.2f%% | %d | %.1f |\n", ball.c_str(), drop,
              recorded.size(), rms * 1000, 100 * rms / drop, fit["evaluations"].get<int>(),
              fit["wall_time_s"].get<double>());
  EXPECT_LE(rms, 0.01 * drop);
  // The answer is the ensemble mean of perturbed free drops, within 1% as well.
  const auto mean = fit["free_run_mean_m"].get<std::vector<double>>();
  ASSERT_EQ(mean.size(), recorded.size());
  double mean_sum = 0;
  for (size_t i = 0; i < recorded.size(); ++i)
    mean_sum += (mean[i] - recorded[i]) * (mean[i] - recorded[i]);
  const double mean_rms = std::sqrt(mean_sum / static_cast<double>(recorded.size()));
  std::printf("| %s ensemble mean | %.2f mm | %.2f%% |\n", ball.c_str(), mean_rms * 1000,
              100 * mean_rms / drop);
  EXPECT_LE(mean_rms, 0.01 * drop);
}

INSTANTIATE_TEST_SUITE_P(Presets, FinalFitOnSynthClip,
                         ::testing::Values("pingpong", "wiffle", "softball", "airball"));

}  // namespace
}  // namespace bouncefit
