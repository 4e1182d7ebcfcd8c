// Several drops of one ball, one fit. Peaks of synth's point mass (a
// softball whose restitution falls with speed: e(v) = 0.42 - 0.03 v) dropped from 1.0 m and
// from 1.6 m, given as two peak files to `bouncefit fit`; the joint answer lists both drops,
// matches both, and predicts drops between them (0.7-1.6 m) within max(5 mm, 3%).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;

std::vector<double> Predict(const fs::path& coeffs, double drop, int members) {
  std::string out;
  const std::string args = fmt::format(" --drop {:.3f} --members {}", drop, members);
  EXPECT_EQ(RunCommand(BouncefitExe() + " predict --json --coeffs " + coeffs.string() + args +
                           " 2>/dev/null", &out), 0) << out;
  return nlohmann::json::parse(out)["bounce_heights_m"].get<std::vector<double>>();
}

TEST(FitJointDrops, TwoPeakFilesFitOneBallThatBouncesLikeBoth) {
  const fs::path dir = testing::ScratchDir("joint_drops");
  const fs::path truth = dir / "truth.json";
  std::ofstream(truth) << R"({"model": "point-mass", "ball": "softball",
      "values": {"restitution": 0.42, "restitution_per_mps": 0.03}})";
  std::string files;
  for (double drop : {1.6, 1.0}) {
    const fs::path csv = dir / ("drop_" + std::to_string(drop).substr(0, 3) + ".csv");
    std::ofstream f(csv);
    f << "bounce,height_m\n0," << drop << "\n";
    const auto h = Predict(truth, drop, 1);
    for (size_t i = 0; i < h.size(); ++i) f << i + 1 << "," << h[i] << "\n";
    files += " --peaks " + csv.string();
  }
  std::string log;
  const fs::path out = dir / "fit";
  ASSERT_EQ(RunCommand(BouncefitExe() + " fit --ball softball --final-only" + files +
                           " --export " + out.string(), &log), 0) << log;
  EXPECT_NE(log.find("drops: 1.0000 m (bounces 1-2), 1.6000 m (3-4)"), std::string::npos) << log;
  const auto fit = nlohmann::json::parse(std::ifstream(out / "coefficients.json"));
  EXPECT_EQ(fit["drop_height_m"].get<double>(), 1.0);  // the last file's drop, then the others
  EXPECT_EQ(fit["other_drop_heights_m"].get<std::vector<double>>(), std::vector<double>{1.6});
  const auto rec = fit["recorded_m"].get<std::vector<double>>();
  const auto sim = fit["simulated_m"].get<std::vector<double>>();
  ASSERT_EQ(rec.size(), 4u);
  ASSERT_EQ(sim.size(), 4u);
  for (size_t i = 0; i < rec.size(); ++i) EXPECT_NEAR(sim[i], rec[i], 0.005) << "bounce " << i + 1;

  for (double drop : {0.7, 1.0, 1.3, 1.6}) {
    const double want = Predict(truth, drop, 1).at(0);
    const double got = Predict(out / "coefficients.json", drop, 8).at(0);
    std::printf("  from %.1f m: truth %.4f m, joint fit %.4f m (%+.1f%%)\n", drop, want, got,
                100 * (got - want) / want);
    EXPECT_LE(std::abs(got - want), std::max(0.005, 0.03 * want)) << drop << " m";
  }
}

// A flag error (exit 2), as for any flag that names a missing file.
TEST(FitJointDrops, AMissingPeakFileIsAOneLineErrorBeforeAnyFit) {
  std::string out;
  EXPECT_EQ(RunCommand(BouncefitExe() +
                           " fit --ball softball --peaks /nonexistent_a.csv --peaks /nonexistent_b.csv",
                       &out), 2) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_NE(out.find("/nonexistent_a.csv"), std::string::npos) << out;
}

}  // namespace
}  // namespace bouncefit
