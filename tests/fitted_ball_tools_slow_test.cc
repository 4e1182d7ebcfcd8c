// The fitted ball's .glb in the tools an animator and a reviewer use: Blender's own glTF
// importer (headless) plays the sample's ball up to the apexes of simulated.csv; the
// Khronos glTF validator finds no error in the sample's, a shared real clip's and a
// `predict --gltf` file; headless Chromium draws the report's 3D view with the ball in it.
// Each skips, saying so, when its tool is absent (scripts/setup-test-tools installs them).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;

const fs::path kTools = fs::path(BOUNCEFIT_SOURCE_DIR) / "tests" / "tools";

bool Have(const std::string& command) {
  std::string out;
  return RunCommand("command -v " + command, &out) == 0;
}

// The built-in sample's run, made once for the tests of this file (they may run at once:
// the lock orders them) and again only when bouncefit is newer than it.
fs::path SampleRun() {
  const fs::path dir = fs::absolute("scratch/fitted_ball_sample_run");
  fs::create_directories(dir.parent_path());
  const std::string d = "'" + dir.string() + "'";
  std::string out;
  const std::string script = "[ " + d + "/report.html -nt " + BouncefitExe() + " ] || { " +
                             BouncefitExe() + " run --speed 0 --lcm-url memq:// --overwrite --out " + d + " && " +
                             BouncefitExe() + " report " + d + "; }";
  EXPECT_EQ(RunCommand("flock " + d + ".lock sh -c \"" + script + "\"", &out), 0) << out;
  return dir;
}

std::vector<std::pair<double, double>> ReadPairs(const fs::path& csv, const char* a, const char* b) {
  std::vector<std::pair<double, double>> rows;
  for (const auto& r : testing::ReadCsv(csv)) rows.emplace_back(std::stod(r.at(a)), std::stod(r.at(b)));
  return rows;
}

TEST(FittedBallInBlender, TheSamplesBallRisesToTheApexesOfSimulatedCsv) {
  if (!Have("blender")) GTEST_SKIP() << "blender not installed (bash scripts/setup-test-tools adds it)";
  const fs::path run = SampleRun();
  const fs::path lowest = testing::ScratchDir("blender") / "lowest.csv";
  std::string out;
  ASSERT_EQ(RunCommand("timeout 300 blender -b --factory-startup --python '" +
                           (kTools / "blender_lowest_point.py").string() + "' -- '" +
                           (run / "fitted_ball.glb").string() + "' fitted_ball '" + lowest.string() + "'",
                       &out),
            0)
      << out;
  ASSERT_NE(out.find("blender_lowest_point: fitted_ball"), std::string::npos) << out;
  const auto played = ReadPairs(lowest, "t_s", "lowest_m");  // s since the release, m
  const auto sim = ReadPairs(run / "simulated.csv", "t_s", "height_m");  // stream s, m
  ASSERT_GT(played.size(), 100u);
  ASSERT_GT(sim.size(), 100u);
  const double release = sim[0].first;
  // An apex: the highest sample within 60 ms either side (a 2 cm bounce flies 128 ms; the
  // turning mesh's lowest point has several local tops per arc).
  const double half_window_s = 0.06;
  int bounces = 0;
  double worst = 0;
  for (size_t i = 1; i < sim.size(); ++i) {
    const auto [t, h] = sim[i];
    if (h < 0.02) continue;
    bool apex = true;
    for (size_t j = 0; j < sim.size() && apex; ++j)
      if (std::abs(sim[j].first - t) <= half_window_s && (sim[j].second > h || (sim[j].second == h && j < i)))
        apex = false;
    if (!apex) continue;
    double top = -1;
    for (const auto& [tp, z] : played)
      if (std::abs(tp - (t - release)) <= half_window_s) top = std::max(top, z);
    EXPECT_NEAR(top, h, 1e-3) << "apex at " << t << " s";
    worst = std::max(worst, std::abs(top - h));
    ++bounces;
  }
  EXPECT_GE(bounces, 10);  // the release and the sample's bounces down to 2 cm
  std::printf("Blender: %d apexes of simulated.csv >= 2 cm, the imported fitted_ball's lowest "
              "point within %.3f mm of each\n", bounces, worst * 1000);
}

TEST(FittedBallValidator, NoErrorInTheSamplesARealClipsAndPredictsFiles) {
  if (!Have("node") || !fs::exists(kTools / "node_modules" / "gltf-validator"))
    GTEST_SKIP() << "node or the npm gltf-validator absent (bash scripts/setup-test-tools adds them)";
  std::vector<fs::path> files{SampleRun() / "fitted_ball.glb"};
  const fs::path dir = testing::ScratchDir("validator");
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " predict --coeffs '" + (SampleRun() / "coefficients.json").string() +
                           "' --drop 0.4 --members 2 --gltf '" + (dir / "predict.glb").string() + "'",
                       &out),
            0)
      << out;
  files.push_back(dir / "predict.glb");
  const fs::path clip = testing::RealClipsDir() / "tennis_ruler_25fps.mp4";
  if (!testing::RealClipsDir().empty() && fs::exists(clip)) {
    ASSERT_EQ(RunCommand(BouncefitExe() + " run '" + clip.string() + "' --ball tennis --speed 0 --out '" +
                             (dir / "real").string() + "'",
                         &out),
              0)
        << out;
    files.push_back(dir / "real" / "fitted_ball.glb");
  } else {
    std::printf("no shared real clips here: validating the sample's and predict's files only\n");
  }
  std::string cmd = "node '" + (kTools / "validate_gltf.mjs").string() + "'";
  for (const auto& f : files) cmd += " '" + f.string() + "'";
  const int rc = RunCommand(cmd, &out);
  std::printf("%s", out.c_str());
  EXPECT_EQ(rc, 0) << out;
  for (const auto& f : files) EXPECT_NE(out.find(f.string() + ": 0 errors"), std::string::npos) << out;
}

TEST(FittedBallReport, ChromiumDrawsTheBallOnTheFloorAtTwoImpacts) {
  std::string chromium;
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"})
    if (Have(name)) {
      chromium = name;
      break;
    }
  if (chromium.empty()) GTEST_SKIP() << "chromium not installed (bash scripts/setup adds it)";
  const fs::path run = SampleRun();
  const std::string html = fs::absolute(run / "report.html").string();
  std::ifstream in(html);
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_NE(page.find("id=\"fitted-ball-glb\""), std::string::npos) << "no 3D view in the page";
  EXPECT_EQ(page.find("<script src="), std::string::npos) << "the page loads a script from elsewhere";
  // The first two impacts (the glb's extras; the sample's ball lands at 0.46 s and 1.19 s).
  const std::regex impacts("\"simulated_impact_times_s\":\\[([0-9.]+),([0-9.]+)");
  std::string json;
  {
    std::ifstream glb(run / "fitted_ball.glb", std::ios::binary);
    json.assign(std::istreambuf_iterator<char>(glb), std::istreambuf_iterator<char>());
  }
  std::smatch m;
  ASSERT_TRUE(std::regex_search(json, m, impacts));
  const fs::path profile = testing::ScratchDir("chromium");
  for (const std::string& t : {m[1].str(), m[2].str()}) {
    std::string dom;
    ASSERT_EQ(RunCommand("timeout 120 " + chromium +
                             " --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader"
                             " --disable-background-networking --no-first-run --user-data-dir='" +
                             (profile / t).string() + "' --window-size=1160,900 --virtual-time-budget=6000"
                             " --dump-dom 'file://" + html + "#t=" + t + "' 2>/dev/null",
                         &dom),
              0);
    std::smatch v;
    ASSERT_TRUE(std::regex_search(dom, v, std::regex("class=\"view3d\"[^>]*>")));
    const std::string tag = v.str();
    ASSERT_NE(tag.find("data-state=\"drawn\""), std::string::npos) << tag;
    std::smatch px;
    ASSERT_TRUE(std::regex_search(tag, px, std::regex("data-drawn-pixels=\"(\\d+)\" data-ball-pixels=\"(\\d+)\"")))
        << tag;
    EXPECT_GT(std::stol(px[1].str()), 10000) << "the floor is not drawn at t = " << t << " s";
    EXPECT_GT(std::stol(px[2].str()), 20) << "the ball is not seen at t = " << t << " s";
    std::printf("t = %s s: %s pixels drawn, %s of the ball\n", t.c_str(), px[1].str().c_str(),
                px[2].str().c_str());
  }
}

}  // namespace
}  // namespace bouncefit
