// `bouncefit synth` as a user runs it: a line of progress a second and a summary, its flags
// into the truth file, bad options as one-line errors, units in its help.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::RunCommand;
using testing::ScratchDir;

int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

TEST(SynthCli, RendersWithProgressAndSummary) {
  const auto dir = ScratchDir("synth_cli");
  std::string out;
  const std::string base = BouncefitExe() + " synth --size 160x120 --fps 60 --duration 2 --ball tennis";
  ASSERT_EQ(RunCommand(base + " --out '" + (dir / "a.avi").string() + "'", &out), 0) << out;
  EXPECT_EQ(Lines(out), 3) << out;  // one per second of output, then the summary
  EXPECT_NE(out.find("120 frames"), std::string::npos) << out;
  EXPECT_NE(out.find("apex heights"), std::string::npos) << out;
  EXPECT_TRUE(std::filesystem::exists(dir / "a.truth.json"));
  ASSERT_EQ(RunCommand(base + " --quiet --roll 5 --distractor --color 10,200,10 --wall-color "
                              "255,255,255 --noise 0 --exposure 0 --out '" +
                           (dir / "b.avi").string() + "'",
                       &out),
            0)
      << out;
  EXPECT_EQ(Lines(out), 1) << out;
  const SynthTruth t = LoadSynthTruth(dir / "b.truth.json");
  EXPECT_EQ(t.roll_deg, 5);
  EXPECT_TRUE(t.distractor);
  EXPECT_EQ(t.ball_color_bgr[1], 200);
  EXPECT_EQ(t.noise_sigma, 0);
}

TEST(SynthCli, BadOptionsAreOneLineErrors) {
  const auto dir = ScratchDir("synth_cli_errors");
  const std::string ok_out = " --out '" + (dir / "x.avi").string() + "'";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--drop-height -1" + ok_out, "drop height"},
      {"--ball frisbee" + ok_out, "frisbee"},
      {"--out /nonexistent-dir/x.avi", "/nonexistent-dir/x.avi"},
      {"--out '" + (dir / "x.mkv").string() + "'", ".mkv"},
      {"--size 320by240" + ok_out, "--size"},
      {"--size 8x8" + ok_out, "size"},
      {"--color 1,2" + ok_out, "--color"},
      {"--wall-color 0,0,300" + ok_out, "--wall-color"},
      {"--fps 0" + ok_out, "fps"},
      {"--duration 0" + ok_out, "duration"},
      {"--exposure 0.5" + ok_out, "exposure"},
      {"--noise -2" + ok_out, "noise"},
      {"--diameter -0.1" + ok_out, "diameter"},
      {"--ball-x 1.5" + ok_out, "ball x"},
      {"--roll 120" + ok_out, "roll"},
      {"--fps" + ok_out, "fps"},
      {"--slow-motion 8 --slow-from 0.2 --slow-to 1" + ok_out, "variable frame rate"},
      {"--floor-pattern carpet" + ok_out, "floor pattern"},
  };
  for (const auto& [args, what] : cases) {
    std::string out;
    EXPECT_NE(RunCommand(BouncefitExe() + " synth " + args, &out), 0) << args;
    EXPECT_EQ(Lines(out), 1) << args << ": " << out;
    EXPECT_NE(out.find("error"), std::string::npos) << args << ": " << out;
    EXPECT_NE(out.find(what), std::string::npos) << args << ": " << out;
  }
}

TEST(SynthCli, HelpGivesUnits) {
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " synth --help", &out), 0);
  for (const char* s : {"metres", "seconds", "pixels", "degrees", "grey levels", "mass, kg",
                        "frames per second", "pingpong", "B,G,R"})
    EXPECT_NE(out.find(s), std::string::npos) << s;
}

}  // namespace
}  // namespace bouncefit
