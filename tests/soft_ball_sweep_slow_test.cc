// The soft-body ball covers the elasticity spectrum: for each of the four ball presets, the
// coefficients stored in model/presets/soft_ball_<preset>.json (found by
// bench/soft_ball_preset_search_bench.cc) put the first three simulated bounce heights
// within 2% of the preset's heights from the point-mass physics synth renders
// (model/point_mass_drop.h); and the rebound boost spans first-rebound ratios from below 0.15
// to above 0.85.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "model/ball_preset.h"
#include "model/point_mass_drop.h"
#include "model/soft_ball_model.h"
#include "tests/point_mass_truth.h"

namespace bouncefit {
namespace {

std::vector<double> PresetHeights(const BallPreset& ball, double drop, int n) {
  const PointMassDropResult r = testing::PointMassTruth(ball, drop, 30);
  std::vector<double> h;
  for (size_t i = 1; i < r.apex_heights_m.size() && int(h.size()) < n; ++i)
    h.push_back(r.apex_heights_m[i]);
  return h;
}

CoefficientValues StoredCoefficients(const std::string& ball, double* drop) {
  const auto path = std::filesystem::path(BOUNCEFIT_SOURCE_DIR) / "model" / "presets" /
                    ("soft_ball_" + ball + ".json");
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  const auto j = nlohmann::json::parse(in);
  *drop = j.at("drop_height_m").get<double>();
  CoefficientValues v;
  for (const auto& [k, x] : j.at("coefficients").items()) v[k] = x.get<double>();
  return v;
}

class PresetSweep : public ::testing::TestWithParam<const char*> {};

TEST_P(PresetSweep, FirstThreeBouncesWithinTwoPercentOfThePreset) {
  const BallPreset ball = *FindBallPreset(GetParam());
  double drop = 0;
  const CoefficientValues v = StoredCoefficients(ball.name, &drop);
  EXPECT_EQ(drop, 1.0);
  const std::vector<double> target = PresetHeights(ball, drop, 3);
  ASSERT_EQ(target.size(), 3u);
  const SoftBallModel model(ball);
  SimulationOptions o;
  o.drop_height_m = drop;
  o.duration_s = 8;
  o.min_bounce_height_m = 0.5 * target.back();
  const SimulationResult r = model.Simulate(v, o);
  ASSERT_TRUE(r.ok) << r.failure;
  ASSERT_GE(r.bounce_heights_m.size(), 3u);
  std::printf("%s (first-rebound ratio %.3f):", ball.name.c_str(), target[0] / drop);
  for (size_t i = 0; i < 3; ++i) {
    const double err = r.bounce_heights_m[i] / target[i] - 1;
    std::printf("  bounce %zu %.5f m vs %.5f m (%+.2f%%)", i + 1, r.bounce_heights_m[i],
                target[i], 100 * err);
    EXPECT_LE(std::abs(err), 0.02) << ball.name << " bounce " << i + 1;
  }
  std::printf("  [%.3f s]\n", r.wall_time_s);
}

INSTANTIATE_TEST_SUITE_P(Presets, PresetSweep,
                         ::testing::Values("pingpong", "wiffle", "softball", "airball"));

// The spectrum: first rebounds from 0.15 (softball) to 0.85 (ping-pong) of the drop,
// without air drag, from the model's default coefficients by sweeping the artificial
// rebound boost (Bullet alone rebounds to ~12% here).
TEST(ElasticitySpectrum, ReboundBoostSpansFirstReboundRatiosFrom015To085) {
  const SoftBallModel model(*FindBallPreset("pingpong"));
  SimulationOptions o;
  o.drop_height_m = 1.0;
  o.duration_s = 1.3;  // the first rebound
  double lowest = 1, highest = 0, previous = -1;
  for (int k = 0; k <= 6; ++k) {
    const double boost = 0.1 * k;
    const SimulationResult r = model.Simulate({{"drag", 0}, {"rebound_boost", boost}}, o);
    ASSERT_TRUE(r.ok) << "boost " << boost << ": " << r.failure;
    ASSERT_FALSE(r.bounce_heights_m.empty());
    const double ratio = r.bounce_heights_m[0] / o.drop_height_m;
    std::printf("rebound_boost %.1f: first-rebound ratio %.3f\n", boost, ratio);
    EXPECT_GT(ratio, previous) << boost;
    previous = ratio;
    lowest = std::min(lowest, ratio);
    highest = std::max(highest, ratio);
  }
  EXPECT_LE(lowest, 0.15);
  EXPECT_GE(highest, 0.85);
}

}  // namespace
}  // namespace bouncefit
