// The capture command as a user runs it: a clip replayed as fast as possible and logged,
// Ctrl-C keeping what was logged, bad input as one line and a non-zero exit.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>

#include "pipeline/lcm_log_replay.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::RunCommand;

TEST(CaptureCommand, ReplaysAClipAsFastAsPossibleAndLogsIt) {
  const auto dir = testing::ScratchDir("capture_command_log");
  const std::string log = (dir / "boxes.lcm").string();
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " capture --replay '" + testing::ShortDropClip() +
                           "' --speed 0 --lcm-url memq:// --log '" + log + "'",
                       &out),
            0)
      << out;
  EXPECT_NE(out.find("capture: done: 180 frames, 0 dropped"), std::string::npos) << out;
  // Every message it sent: STREAM at the start and the end, a box per frame between them.
  LcmLogReader reader(log);
  std::vector<std::string> channels;
  while (auto e = reader.Next()) channels.push_back(e->channel);
  ASSERT_EQ(channels.size(), 182u);
  EXPECT_EQ(channels.front(), "STREAM");
  EXPECT_EQ(channels.back(), "STREAM");
  EXPECT_EQ(std::count(channels.begin(), channels.end(), "BALL_BOX"), 180);
}

TEST(CaptureCommand, CtrlCStopsCleanlyAndKeepsTheLog) {
  const auto dir = testing::ScratchDir("capture_command_sigint");
  const std::string log = (dir / "boxes.lcm").string();
  std::string out;
  // The 1.5 s clip replayed at half speed (3 s), interrupted 0.5 s after its first box is
  // logged: start-up time on a loaded machine cannot move the stop out of the stream.
  const int rc = RunCommand(
      "bash -c \"" + BouncefitExe() + " capture --replay '" + testing::ShortDropClip() +
          "' --speed 0.5 --lcm-url memq:// --quiet --log '" + log +
          "' & P=\\$!; for i in \\$(seq 500); do [ -s '" + log +
          "' ] && break; sleep 0.02; done; sleep 0.5; kill -INT \\$P; wait \\$P\"",
      &out);
  EXPECT_EQ(rc, 130) << out;  // stopped by the user, after writing what was recorded
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("capture: stopped: (\\d+) frames"))) << out;
  const int frames = std::stoi(m[1]);
  EXPECT_GT(frames, 20);
  EXPECT_LT(frames, 170);
  // Every box published before the stop is in the log, between STREAM's start and end, and
  // the log is whole.
  LcmLogReader reader(log);
  int n = 0;
  while (reader.Next()) ++n;
  EXPECT_EQ(n, frames + 2);
}

TEST(CaptureCommand, BadInputIsOneLineAndNonZero) {
  const auto dir = testing::ScratchDir("capture_command_errors");
  const std::string exe = BouncefitExe() + " capture ";
  std::string out;
  const std::string missing = (dir / "missing.avi").string();
  EXPECT_EQ(RunCommand(exe + "--replay '" + missing + "' --lcm-url memq://", &out), 1);
  EXPECT_EQ(out, "bouncefit capture: error: cannot open video '" + missing + "': no such file\n");

  const std::string junk = (dir / "junk.avi").string();
  {
    std::ofstream f(junk, std::ios::binary);
    for (int i = 0; i < 50000; ++i) f.put(static_cast<char>((i * 7919) % 251));
  }
  EXPECT_EQ(RunCommand(exe + "--replay '" + junk + "' --lcm-url memq://", &out), 1);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_EQ(out.rfind("bouncefit capture: error: ", 0), 0u) << out;

  EXPECT_EQ(RunCommand(exe + "--device /dev/video-none --lcm-url memq://", &out), 1);
  EXPECT_EQ(out, "bouncefit capture: error: cannot open /dev/video-none: No such file or directory\n");
  EXPECT_EQ(RunCommand(exe + "--lcm-url memq://", &out), 2);
  EXPECT_EQ(out, "bouncefit capture: error: give exactly one of --replay CLIP or --device /dev/videoN\n");
  EXPECT_EQ(RunCommand(exe + "--replay x.avi --speed -2", &out), 2);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_EQ(RunCommand(exe + "--replay x.avi --frobnicate", &out), 2);
  EXPECT_EQ(RunCommand(exe + "--device /dev/video0 --size 640by480 --lcm-url memq://", &out), 2);
}

TEST(CaptureCommand, ListsDevicesOrSaysThereAreNone) {
  std::string out;
  EXPECT_EQ(RunCommand(BouncefitExe() + " capture --list-devices", &out), 0);
  if (std::filesystem::exists("/dev/video0"))
    EXPECT_NE(out.find("/dev/video"), std::string::npos) << out;
  else
    EXPECT_EQ(out, "no V4L2 capture device (/dev/video*) on this machine\n");
  if (!std::filesystem::exists("/dev/video0")) {
    EXPECT_EQ(RunCommand(BouncefitExe() + " capture --list-formats", &out), 1);
    EXPECT_EQ(out, "bouncefit capture: error: cannot open /dev/video0: No such file or directory\n");
  }
}

}  // namespace
}  // namespace bouncefit
