// One pipeline, hosted anywhere: the capture, detect and fit nodes as three processes over UDP
// multicast, at capture's own pace, fill an output directory as `run` does in one process:
// peaks.csv and impacts.csv byte for byte, and final fits whose simulated heights agree.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "msgs/peaks_csv.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;

// The three nodes, each a process of its own, into `out`; returns what they printed.
std::string RunThreeNodes(const fs::path& clip, const std::string& ball, const fs::path& out) {
  const std::string url = testing::UniqueUdpmUrl();
  const std::string exe = BouncefitExe();
  const std::string script =
      exe + " fit --ball " + ball + " --lcm-url '" + url + "' --out " + out.string() + " --exit-after-idle 5 > " +
      out.string() + ".fit.txt 2>&1 & F=$!; " + exe + " detect --ball " + ball + " --lcm-url '" + url +
      "' --out " + out.string() + " --exit-after-idle 5 > " + out.string() + ".detect.txt 2>&1 & D=$!; sleep 1; " +
      exe + " capture --replay " + clip.string() + " --lcm-url '" + url + "' --out " + out.string() +
      " --quiet; wait $D; wait $F; true";
  std::string printed;
  RunCommand("bash -c \"" + script + "\"", &printed);
  return printed + testing::ReadFile(out.string() + ".detect.txt") + testing::ReadFile(out.string() + ".fit.txt");
}

void ExpectSameAsRun(const fs::path& clip, const std::string& ball, const std::string& name) {
  const fs::path dir = testing::ScratchDir(name);
  std::string run_out;
  const int rc = RunCommand(BouncefitExe() + " run " + clip.string() + " --ball " + ball + " --out " +
                                (dir / "run").string() + " --speed 0 --lcm-url memq://",
                            &run_out);
  ASSERT_TRUE(rc == 0 || rc == 4) << run_out;
  const std::string nodes_out = RunThreeNodes(clip, ball, dir / "nodes");
  for (const char* file : {"peaks.csv", "impacts.csv"}) {
    ASSERT_TRUE(fs::exists(dir / "nodes" / file)) << file << "\n" << nodes_out;
    EXPECT_EQ(testing::ReadFile(dir / "run" / file), testing::ReadFile(dir / "nodes" / file)) << file << "\n" << nodes_out;
  }
  const size_t rows = ReadPeaksCsv(dir / "run" / "peaks.csv").size();
  EXPECT_GE(rows, 2u);
  // A person reads each bounce once: as many `peak` lines as rows (revisions are indented).
  size_t peak_lines = 0;
  for (size_t at = 0; (at = run_out.find("\npeak ", at)) != std::string::npos; ++at) ++peak_lines;
  EXPECT_EQ(peak_lines, rows) << run_out;
  // Each node wrote what it owns, as run did.
  for (const char* file : {"track.csv", "session.lcm", "calibration.json", "summary.json", "fit.jsonl"})
    EXPECT_TRUE(fs::exists(dir / "nodes" / file)) << file;
  const bool run_fitted = fs::exists(dir / "run" / "coefficients.json");
  ASSERT_EQ(fs::exists(dir / "nodes" / "coefficients.json"), run_fitted) << nodes_out;
  if (!run_fitted) return;
  const auto a = nlohmann::json::parse(std::ifstream(dir / "run" / "coefficients.json"));
  const auto b = nlohmann::json::parse(std::ifstream(dir / "nodes" / "coefficients.json"));
  ASSERT_EQ(a["simulated_m"].size(), b["simulated_m"].size());
  for (size_t i = 0; i < a["simulated_m"].size(); ++i)
    EXPECT_NEAR(a["simulated_m"][i].get<double>(), b["simulated_m"][i].get<double>(), 1e-4) << "bounce " << i + 1;
  EXPECT_TRUE(fs::exists(dir / "nodes" / "fitted_ball"));
  EXPECT_TRUE(fs::exists(dir / "nodes" / "simulated.csv"));
}

TEST(PipelineNodes, TheBuiltInSampleAsThreeProcessesFillsTheDirectoryAsRunDoes) {
  const fs::path cache = testing::ScratchDir("cache");
  std::string out;
  // Renders the sample into this cache, once.
  ASSERT_EQ(RunCommand("XDG_CACHE_HOME=" + cache.string() + " " + BouncefitExe() + " run --out " +
                           (cache / "first").string() + " --speed 0 --lcm-url memq:// --no-fit",
                       &out),
            0)
      << out;
  const fs::path clip = cache / "bouncefit" / "sample-v1-pingpong-1m.avi";
  ASSERT_TRUE(fs::exists(clip)) << out;
  ExpectSameAsRun(clip, "pingpong", "sample");
}

TEST(PipelineNodes, RealClipsWithSoundAsThreeProcessesGiveRunsPeaksAndImpacts) {
  const fs::path clips = testing::RealClipsDir();
  if (clips.empty()) GTEST_SKIP() << "no ../shared/real-clips on this machine";
  ExpectSameAsRun(clips / "basketball_tile_ochre_24fps.mp4", "basketball", "basketball");
  ExpectSameAsRun(clips / "tennis_door_wood_20fps.mp4", "tennis", "tennis_door");
}

}  // namespace
}  // namespace bouncefit
