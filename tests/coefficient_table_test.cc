// The soft-body coefficient tables built into the binary (model/CMakeLists.txt embeds
// model/presets/*.json), $BOUNCEFIT_PRESETS_DIR overriding them, and `simulate --coeffs preset`
// from a copy of the binary with the source tables hidden.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "fit/fit_models.h"
#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/soft_ball_model.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

const char* const kBalls[] = {"pingpong", "wiffle", "softball", "airball"};

std::filesystem::path SourcePresets() {
  return std::filesystem::path(BOUNCEFIT_SOURCE_DIR) / "model" / "presets";
}

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << path;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Sets (or, with nullopt, unsets) an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::optional<std::string>& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) ::setenv(name, value->c_str(), 1);
    else ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_) ::setenv(name_, old_->c_str(), 1);
    else ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void WriteFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

TEST(FitPresets, EmbeddedTextIsEverySourceFileVerbatim) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(SourcePresets())) {
    if (e.path().extension() != ".json") continue;
    const std::string name = e.path().filename().string();
    names.insert(name);
    const auto text = EmbeddedPresetText(name);
    ASSERT_TRUE(text) << name;
    EXPECT_EQ(std::string(*text), ReadText(e.path())) << name;
  }
  for (const char* ball : kBalls)
    EXPECT_TRUE(names.count(std::string("soft_ball_") + ball + ".json")) << ball;
  EXPECT_FALSE(EmbeddedPresetText("soft_ball_nosuchball.json"));
  EXPECT_FALSE(EmbeddedPresetText("presets/soft_ball_pingpong.json"));  // names, not paths
}

TEST(FitPresets, EachBallsTableIsTheEmbeddedSourceFile) {
  const ScopedEnv env("BOUNCEFIT_PRESETS_DIR", std::nullopt);
  for (const char* ball : kBalls) {
    const std::string file = std::string("soft_ball_") + ball + ".json";
    const auto table = SoftBallPresetTable(ball);
    ASSERT_TRUE(table) << ball;
    EXPECT_EQ(table->source, "embedded model/presets/" + file);
    const CoefficientTable source = LoadCoefficientTable(SourcePresets() / file);
    EXPECT_EQ(table->values, source.values) << ball;
    EXPECT_FALSE(table->values.empty()) << ball;
    // What the coefficients hold for comes along: the model's step and iterations.
    const SoftBallModel model(*FindBallPreset(ball));
    EXPECT_EQ(table->time_step_s, model.config().time_step_s) << ball;
    EXPECT_EQ(table->position_iterations, model.config().position_iterations) << ball;
  }
}

TEST(FitPresets, PresetsDirOverridesBallByBall) {
  const auto dir = testing::ScratchDir("presets");
  WriteFile(dir / "soft_ball_pingpong.json", R"({"coefficients": {"drag": 0.123}})");
  const ScopedEnv env("BOUNCEFIT_PRESETS_DIR", dir.string());
  const auto pingpong = SoftBallPresetTable("pingpong");
  ASSERT_TRUE(pingpong);
  EXPECT_EQ(pingpong->source, (dir / "soft_ball_pingpong.json").string());
  EXPECT_EQ(pingpong->values, (CoefficientValues{{"drag", 0.123}}));
  EXPECT_FALSE(pingpong->time_step_s);
  // No file there for the wiffle ball: its embedded table.
  const auto wiffle = SoftBallPresetTable("wiffle");
  ASSERT_TRUE(wiffle);
  EXPECT_EQ(wiffle->source, "embedded model/presets/soft_ball_wiffle.json");
  // The boost's warm start follows the override (the restitution law starts from the
  // model's defaults and the ball's curve, not from a table fitted with the boost).
  const BallPreset ball = *FindBallPreset("pingpong");
  const SoftBallModel model(ball);
  FitSessionConfig config;
  config.impact = "boost";
  ConfigureSessionForModel(model, ball, &config);
  EXPECT_EQ(config.start, (CoefficientValues{{"drag", 0.123}}));
}

TEST(FitPresets, ABallWithNoTableHasNone) {
  {
    const ScopedEnv env("BOUNCEFIT_PRESETS_DIR", std::nullopt);
    EXPECT_FALSE(SoftBallPresetTable("nosuchball"));
  }
  const auto dir = testing::ScratchDir("presets");
  const ScopedEnv env("BOUNCEFIT_PRESETS_DIR", dir.string());
  EXPECT_FALSE(SoftBallPresetTable("nosuchball"));
  // A custom ball (say --diameter and --mass on a name of one's own) gets no warm start.
  BallPreset ball = *FindBallPreset("pingpong");
  ball.name = "nosuchball";
  FitSessionConfig config;
  config.impact = "boost";
  ConfigureSessionForModel(SoftBallModel(ball), ball, &config);
  EXPECT_TRUE(config.start.empty());
  // The restitution law starts from the ball's own curve whatever its name.
  FitSessionConfig law;
  law.impact = "restitution";
  ConfigureSessionForModel(SoftBallModel(ball), ball, &law);
  EXPECT_EQ(law.start.at("rebound_restitution"), ball.restitution);
  EXPECT_EQ(law.start.at("drag"), ball.drag_coefficient);
}

TEST(FitPresets, BrokenOverrideIsAOneLineError) {
  const auto dir = testing::ScratchDir("presets");
  WriteFile(dir / "soft_ball_wiffle.json", "{\"coefficients\": \n{oops");
  const ScopedEnv env("BOUNCEFIT_PRESETS_DIR", dir.string());
  try {
    SoftBallPresetTable("wiffle");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind((dir / "soft_ball_wiffle.json").string() + ": not JSON", 0), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// The lookup does not go through the source path: from another working directory, with
// no override, the tables are there all the same.
TEST(FitPresets, LookupNeedsNeitherSourceTreeNorWorkingDirectory) {
  const auto dir = testing::ScratchDir("elsewhere");
  const auto cwd = std::filesystem::current_path();
  const ScopedEnv env("BOUNCEFIT_PRESETS_DIR", std::nullopt);
  std::filesystem::current_path(dir);
  for (const char* ball : kBalls) {
    const auto table = SoftBallPresetTable(ball);
    EXPECT_TRUE(table && !table->values.empty()) << ball;
  }
  std::filesystem::current_path(cwd);
}

// `simulate --coeffs preset` from a copy of the binary in a folder of its own, run there with
// no override and model/presets/ hidden (an empty tmpfs over it, in a user and mount namespace
// of its own, where the machine allows one): the stored coefficients, as the source file
// holds them.
TEST(FitPresets, CopiedBinarySimulatesItsPresetWithTheSourceHidden) {
  const auto dir = testing::ScratchDir("bin");
  std::filesystem::copy_file(BOUNCEFIT_EXE, dir / "bouncefit");
  const std::string run = "cd '" + dir.string() +
                          "' && env -u BOUNCEFIT_PRESETS_DIR ./bouncefit simulate --ball pingpong "
                          "--coeffs preset --json --no-trajectory --duration 1.5";
  const std::string hide = "mount -t tmpfs none '" + SourcePresets().string() + "' && ls -A '" +
                           SourcePresets().string() + "' | wc -l | grep -qx 0";
  std::string out;
  const bool hidden = testing::RunCommand("unshare -rm sh -c \"" + hide + "\"", &out) == 0;
  if (!hidden) std::printf("(model/presets/ not hidden, no user namespaces here: %s)\n", out.c_str());
  ASSERT_EQ(testing::RunCommand(hidden ? "unshare -rm sh -c \"" + hide + " && " + run + "\"" : run,
                                &out),
            0)
      << out;
  const auto j = nlohmann::json::parse(out);
  const auto source = nlohmann::json::parse(ReadText(SourcePresets() / "soft_ball_pingpong.json"));
  for (const auto& [name, value] : source.at("coefficients").items())
    EXPECT_EQ(j.at("coefficients").at(name), value) << name;
  EXPECT_FALSE(j.at("bounce_heights_m").empty());
}

// An override whose time step is not the model's: refused, naming the file, on one line.
TEST(FitPresets, SimulateRefusesAnOverrideForAnotherTimeStep) {
  const auto dir = testing::ScratchDir("presets");
  WriteFile(dir / "soft_ball_airball.json",
            R"({"time_step_s": 0.01, "coefficients": {"drag": 0.5}})");
  std::string out;
  EXPECT_EQ(testing::RunCommand("BOUNCEFIT_PRESETS_DIR='" + dir.string() + "' " +
                                    testing::BouncefitExe() +
                                    " simulate --ball airball --coeffs preset --no-trajectory",
                                &out),
            1);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_EQ(out.rfind("bouncefit simulate: error: " + (dir / "soft_ball_airball.json").string() +
                          ": coefficients for time step 0.01 s",
                      0),
            0u)
      << out;
}

}  // namespace
}  // namespace bouncefit
