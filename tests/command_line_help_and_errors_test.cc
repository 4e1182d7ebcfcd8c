// The command line as a user meets it: help everywhere, one-line errors, non-zero exits.
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::RunCommand;

const char* kSubcommands[] = {"run",    "capture", "detect",   "fit",       "watch",
                              "report", "synth",   "simulate", "replay-log"};

TEST(Cli, TopLevelHelpListsEverySubcommand) {
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " --help", &out), 0) << out;
  for (const char* sub : kSubcommands) EXPECT_NE(out.find(sub), std::string::npos) << sub;
}

TEST(Cli, EverySubcommandHasHelp) {
  for (const char* sub : kSubcommands) {
    std::string out;
    EXPECT_EQ(RunCommand(BouncefitExe() + " " + sub + " --help", &out), 0) << sub << out;
    EXPECT_NE(out.find("Usage"), std::string::npos) << sub << out;
  }
}

int LineCount(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

TEST(Cli, WrongFlagIsOneLineErrorAndNonZero) {
  for (const char* sub : kSubcommands) {
    std::string out;
    EXPECT_NE(RunCommand(BouncefitExe() + " " + sub + " --no-such-flag", &out), 0) << sub;
    EXPECT_EQ(LineCount(out), 1) << sub << ": " << out;
    EXPECT_NE(out.find("error"), std::string::npos) << out;
  }
}

// Flags that contradict each other: a bad flag, one line naming both (the scale's rule is the
// calibrator config's, in its words).
TEST(Cli, ExclusiveFlagsAreOneLineErrors) {
  const std::pair<const char*, const char*> cases[] = {
      {"--retime-frames --keep-frame-times", "--retime-frames excludes --keep-frame-times"},
      {"--drop-height 1 --px-per-m 300", "a px per metre scale or a drop height, not both"},
  };
  for (const char* sub : {"run", "detect"})
    for (const auto& [args, says] : cases) {
      std::string out;
      EXPECT_EQ(RunCommand(BouncefitExe() + " " + sub + " " + args, &out), 2) << sub << " " << args;
      EXPECT_EQ(LineCount(out), 1) << sub << ": " << out;
      EXPECT_NE(out.find(says), std::string::npos) << out;
    }
}

TEST(Cli, UnknownSubcommandAndNoSubcommandFail) {
  std::string out;
  EXPECT_NE(RunCommand(BouncefitExe() + " frobnicate", &out), 0);
  EXPECT_EQ(LineCount(out), 1) << out;
  EXPECT_NE(RunCommand(BouncefitExe(), &out), 0);
  EXPECT_EQ(LineCount(out), 1) << out;
  // --help does not make an unknown command known (it printed the main help, exit 0).
  EXPECT_NE(RunCommand(BouncefitExe() + " frobnicate --help", &out), 0);
  EXPECT_EQ(LineCount(out), 1) << out;
  EXPECT_NE(out.find("frobnicate"), std::string::npos) << out;
}

// The lines of one group ("Ball:") in a command's --help, up to the blank line after them.
std::string HelpGroup(const std::string& command, const std::string& group) {
  std::string out;
  EXPECT_EQ(RunCommand(BouncefitExe() + " " + command + " --help", &out), 0) << command << out;
  const size_t start = out.find("\n" + group + ":\n");
  if (start == std::string::npos) return "";
  const size_t end = out.find("\n\n", start + 1);
  return out.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

// One ball flag, one meaning: every command that takes a ball says it in the same words.
TEST(Cli, BallFlagsReadTheSameOnEveryCommand) {
  const std::string run = HelpGroup("run", "Ball");
  for (const char* flag : {"--ball", "--diameter", "--mass"}) EXPECT_NE(run.find(flag), std::string::npos) << run;
  for (const char* sub : {"detect", "fit", "predict", "simulate", "synth"})
    EXPECT_EQ(HelpGroup(sub, "Ball"), run) << sub;
}

TEST(Cli, ScaleAndClockFlagsReadTheSameOnRunAndDetect) {
  for (const char* group : {"Scale", "Clock"}) {
    EXPECT_FALSE(HelpGroup("run", group).empty()) << group;
    EXPECT_EQ(HelpGroup("detect", group), HelpGroup("run", group)) << group;
  }
}

// A number out of its range says which range in a line a person reads: CLI11's own check
// printed the largest double, 309 digits, as the upper end.
TEST(Cli, NumberOutOfRangeSaysTheRangeBriefly) {
  const std::pair<const char*, const char*> cases[] = {
      {"run --speed -1", "--speed: must be a number >= 0, not -1"},
      {"run --diameter 0", "--diameter: must be a number > 0, not 0"},
      {"synth -o x.avi --restitution -0.5", "--restitution: must be a number >= 0, not -0.5"},
      {"detect --frame-size 640,-480", "--frame-size: must be a number > 0, not -480"},
      {"detect --frame-size 640", "--frame-size: At least 2 required but received 1"},
  };
  for (const auto& [args, says] : cases) {
    std::string out;
    EXPECT_NE(RunCommand(BouncefitExe() + " " + args, &out), 0) << args;
    EXPECT_EQ(LineCount(out), 1) << args << ": " << out;
    EXPECT_NE(out.find(says), std::string::npos) << args << ": " << out;
    EXPECT_LT(out.size(), 160u) << out;
  }
}

}  // namespace
}  // namespace bouncefit
