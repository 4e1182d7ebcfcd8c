// `run`'s contract with a script: what its exit status means, an output directory that never
// mixes two runs, and a scale flag the measurement contradicts refused before anything is written.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "msgs/peaks_csv.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;

// The built-in sample, rendered once into this test's cache.
fs::path Sample() {
  static const fs::path clip = [] {
    const fs::path cache = testing::ScratchDir("cache");
    std::string out;
    RunCommand("XDG_CACHE_HOME=" + cache.string() + " " + BouncefitExe() + " run --out " + (cache / "first").string() +
                   " --speed 0 --lcm-url memq:// --no-fit",
               &out);
    return cache / "bouncefit" / "sample-v1-pingpong-1m.avi";
  }();
  return clip;
}

int RunBouncefit(const std::string& args, std::string* out) {
  return RunCommand(BouncefitExe() + " run " + args + " --speed 0 --lcm-url memq://", out);
}

TEST(RunExitStatus, VersionIsAnAnswer) {
  std::string out;
  EXPECT_EQ(RunCommand(BouncefitExe() + " --version", &out), 0) << out;
  EXPECT_EQ(out.rfind("bouncefit ", 0), 0u) << out;
}

TEST(RunExitStatus, ZeroForAnAnswerThreeForAStillClipWithNoBall) {
  const fs::path dir = testing::ScratchDir("codes");
  std::string out;
  EXPECT_EQ(RunBouncefit(Sample().string() + " --no-fit --out " + (dir / "peaks").string(), &out), 0) << out;
  EXPECT_GE(ReadPeaksCsv(dir / "peaks" / "peaks.csv").size(), 5u);
  const fs::path still = dir / "still.mp4";
  ASSERT_EQ(RunCommand("ffmpeg -v error -y -f lavfi -i color=c=gray:s=320x240:r=30 -t 1 -pix_fmt yuv420p '" +
                           still.string() + "'",
                       &out),
            0)
      << out;
  EXPECT_EQ(RunBouncefit(still.string() + " --out " + (dir / "still").string(), &out), 3) << out;
  EXPECT_NE(out.find("no ball found"), std::string::npos) << out;
}

TEST(RunExitStatus, FourForBouncesNoBallModelExplains) {
  // Rebounds no restitution law explains (0.9 of the drop, then 0.2): "no fit: <why>" and exit 4,
  // never an answer; nothing exported.
  const fs::path dir = testing::ScratchDir("nofit");
  std::string out;
  const int rc = RunCommand(BouncefitExe() + " fit --heights 1.0,0.9,0.2,0.15 --ball pingpong --final-only --export " +
                                (dir / "out").string(),
                            &out);
  EXPECT_EQ(rc, 4) << out;
  EXPECT_NE(out.find("no fit: "), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "out" / "coefficients.json"));
}

TEST(RunExitStatus, OneHundredThirtyWhenStoppedAfterWritingWhatWasRecorded) {
  const fs::path dir = testing::ScratchDir("stopped");
  const std::string clip = Sample().string();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string out = (dir / "out").string();
    const std::string log = out + ".txt";
    FILE* f = std::fopen(log.c_str(), "w");
    if (f) ::dup2(fileno(f), 1), ::dup2(fileno(f), 2);
    ::execl(BOUNCEFIT_EXE, "bouncefit", "run", clip.c_str(), "--out", out.c_str(), "--lcm-url", "memq://",
            "--no-fit", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // paced: the release and a rebound
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_TRUE(fs::exists(dir / "out" / "track.csv"));
  EXPECT_TRUE(fs::exists(dir / "out" / "summary.json"));
  EXPECT_GE(ReadPeaksCsv(dir / "out" / "peaks.csv").size(), 1u);
}

// A node waiting on an idle bus and stopped by Ctrl-C exits as stopped (130), not as a failed
// bus (1): the signal interrupts its wait for a message.
TEST(RunExitStatus, AnIdleNodeStoppedByCtrlCIsStopped) {
  for (const char* node : {"detect", "fit"}) {
    const fs::path dir = testing::ScratchDir(std::string("idle_") + node);
    const std::string log = (dir / "log.txt").string();
    const pid_t pid = ::fork();
    if (pid == 0) {
      FILE* f = std::fopen(log.c_str(), "w");
      if (f) ::dup2(fileno(f), 1), ::dup2(fileno(f), 2);
      ::execl(BOUNCEFIT_EXE, "bouncefit", node, "--lcm-url", "memq://", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    ::kill(pid, SIGINT);
    int status = 0;
    ::waitpid(pid, &status, 0);
    std::ifstream in(log);
    const std::string out((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_TRUE(WIFEXITED(status)) << node << ": " << out;
    EXPECT_EQ(WEXITSTATUS(status), 130) << node << ": " << out;
  }
}

TEST(RunExitStatus, AnEarlierRunIsRefusedOrClearedWithOverwrite) {
  const fs::path dir = testing::ScratchDir("overwrite");
  const fs::path out_dir = dir / "out";
  std::string out;
  ASSERT_EQ(RunBouncefit(Sample().string() + " --model point-mass --out " + out_dir.string(), &out), 0) << out;
  ASSERT_TRUE(fs::exists(out_dir / "coefficients.json"));
  const std::string before = std::to_string(fs::last_write_time(out_dir / "peaks.csv").time_since_epoch().count());
  EXPECT_EQ(RunBouncefit(Sample().string() + " --no-fit --out " + out_dir.string(), &out), 1) << out;
  EXPECT_NE(out.find("holds an earlier run"), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_EQ(std::to_string(fs::last_write_time(out_dir / "peaks.csv").time_since_epoch().count()), before);
  // --overwrite clears the earlier run's files first: no coefficients of another run stay.
  EXPECT_EQ(RunBouncefit(Sample().string() + " --no-fit --overwrite --out " + out_dir.string(), &out), 0) << out;
  EXPECT_FALSE(fs::exists(out_dir / "coefficients.json"));
  EXPECT_FALSE(fs::exists(out_dir / "fitted_ball"));
  EXPECT_TRUE(fs::exists(out_dir / "peaks.csv"));
}

TEST(RunExitStatus, AScaleTheMeasurementContradictsIsABadFlagAndWritesNothing) {
  const fs::path dir = testing::ScratchDir("contradicted");
  std::string out;
  for (const char* flag : {"--px-per-m 1000000", "--drop-height 1000"}) {
    const fs::path o = dir / "out";
    EXPECT_EQ(RunBouncefit(Sample().string() + " --no-fit " + flag + " --out " + o.string(), &out), 2) << flag << ": " << out;
    EXPECT_NE(out.find("contradicts the measurement"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(o / "peaks.csv")) << flag;
    EXPECT_FALSE(fs::exists(o / "track.csv")) << flag;
  }
  // --force insists: the run goes through on the given scale.
  EXPECT_EQ(RunBouncefit(Sample().string() + " --no-fit --px-per-m 1000000 --force --out " + (dir / "forced").string(), &out), 0)
      << out;
}

}  // namespace
}  // namespace bouncefit
