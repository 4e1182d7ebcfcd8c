// A variable frame rate, rendered with known truth and run with nothing but the ball: a
// phone's slow motion without a tag (taken at 240 fps, a span holding several bounces stamped
// 4x or 8x slowed, real time either side, with or without ramps, and on a phone's 1/600 s
// tick) and a phone's ordinary video whose rate wanders between 26 and 30 fps. Every apex of
// 2 cm or more found within max(2 mm, 2%) of its real height, at its real time, no row that is
// no apex, every frame in flight found, the scale within 2%. Read as stamped
// (--keep-frame-times), the slow motion loses its bounces.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "synth/synth_truth.h"
#include "tests/synth_run_score.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

struct VariableClip {
  const char* name;
  const char* synth_flags;
  const char* ball;
  bool slowed;  // the stamps hold slow motion
  const char* container = ".mp4";
  // > 0: re-stamped as a phone writes its file, on a 1/phone_tick s tick half a tick early and
  // the first picture at 0 (at 240 fps on 1/600 s: steps of 2, 2, 3, 2, 3 ... ticks).
  int phone_tick = 0;
};

// ctest's test names show the clip's name, not the parameter's bytes.
void PrintTo(const VariableClip& c, std::ostream* os) { *os << c.name; }

class VariableRate : public ::testing::TestWithParam<VariableClip> {};

std::string Name(const ::testing::TestParamInfo<VariableClip>& info) { return info.param.name; }

struct Score {
  int wanted = 0, within = 0, false_rows = 0;
  int in_flight = 0, lost_in_flight = 0;  // frames with the whole ball in view in flight
  double scale_ratio = 0;
  std::string table;
};

// peaks.csv against the truth's apexes (real times): a row within 60 ms of an apex is its
// row; an apex of 2 cm or more must have one within max(2 mm, 2%); a row of no apex is false.
Score ScoreRun(const SynthTruth& truth, const std::filesystem::path& out) {
  Score s;
  const auto rows = testing::ReadCsv(out / "peaks.csv");
  std::vector<bool> used(rows.size(), false);
  const double end_s = truth.frames.back().t_s;
  for (size_t k = 0; k < truth.apex_times_s.size(); ++k) {
    const double t = truth.apex_times_s[k], h = truth.apex_heights_m[k];
    if (t < 1.5 / truth.fps || t > end_s - 1.5 / truth.fps) continue;
    int best = -1;
    double nearest = 0.06;
    for (size_t j = 0; j < rows.size(); ++j)
      if (const double d = std::abs(std::stod(rows[j].at("t_s")) - t); d < nearest) best = static_cast<int>(j), nearest = d;
    if (best >= 0) used[static_cast<size_t>(best)] = true;
    if (h < 0.02) continue;
    ++s.wanted;
    const double got = best >= 0 ? std::stod(rows[static_cast<size_t>(best)].at("height_m")) : NAN;
    const bool ok = std::abs(got - h) <= std::max(0.002, 0.02 * h);
    s.within += ok;
    s.table += fmt::format("  apex {} at {:.3f} s: {:.4f} m, found {:.4f} m{}\n", k, t, h, got, ok ? "" : " OFF");
  }
  for (size_t j = 0; j < rows.size(); ++j)
    if (!used[j]) {
      ++s.false_rows;
      s.table += "  false row at " + rows[j].at("t_s") + " s: " + rows[j].at("height_m") + " m\n";
    }
  const testing::InFlightScore f = testing::ScoreInFlight(truth, out);
  s.in_flight = f.in_flight, s.lost_in_flight = f.lost;
  if (f.lost > 0) s.table += "  frames in flight not found:" + f.lost_frames + "\n";
  std::ifstream cal(out / "calibration.json");
  if (cal) {
    const auto c = nlohmann::json::parse(cal);
    if (c.contains("px_per_m") && c["px_per_m"].is_number())
      s.scale_ratio = c["px_per_m"].get<double>() / truth.px_per_m;
  }
  return s;
}

TEST_P(VariableRate, EveryApexInRealMetresAtItsRealTime) {
  const VariableClip c = GetParam();
  const auto dir = testing::ScratchDir(std::string("variable_rate_") + c.name);
  const auto rendered = dir / (std::string("clip") + c.container);
  std::string log;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " synth -q -o '" + rendered.string() + "' --ball " +
                                    c.ball + " " + c.synth_flags,
                                &log),
            0)
      << log;
  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(rendered));
  auto clip = rendered;
  if (c.phone_tick > 0) {
    const std::string tick = std::to_string(c.phone_tick);
    clip = dir / (std::string("phone") + c.container);
    ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -i '" + rendered.string() + "' -vf \"setpts='max(0,floor(T*" +
                                      tick + "-0.5))/(" + tick + "*TB)'\" -fps_mode passthrough -enc_time_base 1/" +
                                      tick + " -c:v mpeg4 -q:v 2 -video_track_timescale " + tick + " '" +
                                      clip.string() + "'",
                                  &log),
              0)
        << log;
  }
  // A run read as stamped may find no bounce at all (its own exit status): only its rows count.
  auto run = [&](const std::string& flags, const std::string& tag, bool must_find = true) {
    const auto o = dir / tag;
    std::string out;
    const int rc = testing::RunCommand(testing::BouncefitExe() + " run '" + clip.string() + "' --ball " + c.ball +
                                           flags + " --speed 0 --no-fit --lcm-url memq:// --overwrite --out '" +
                                           o.string() + "'",
                                       &out);
    if (must_find) {
      EXPECT_EQ(rc, 0) << out;
    }
    return o;
  };
  const auto o = run("", "default");
  const auto summary = nlohmann::json::parse(std::ifstream(o / "summary.json"));
  const Score s = ScoreRun(truth, o);
  std::printf("%s: %d of %d apexes within max(2 mm, 2%%), %d false rows, %d of %d frames in flight lost, scale "
              "%.4f x the truth's\n%s",
              c.name, s.within, s.wanted, s.false_rows, s.lost_in_flight, s.in_flight, s.scale_ratio, s.table.c_str());
  EXPECT_GE(s.wanted, c.slowed ? 3 : 2);
  EXPECT_EQ(s.within, s.wanted) << s.table;
  EXPECT_EQ(s.false_rows, 0) << s.table;
  EXPECT_GT(s.in_flight, 0);
  EXPECT_EQ(s.lost_in_flight, 0) << s.table;
  EXPECT_NEAR(s.scale_ratio, 1.0, 0.02);
  const auto& capture = summary["clock"]["capture_clock"];
  if (c.slowed) {
    ASSERT_TRUE(capture.is_object()) << summary["clock"].dump();
    EXPECT_NEAR(capture["capture_fps"].get<double>(), truth.fps, 0.01 * truth.fps);
    // The stamps alone: a fall that slows to a crawl in mid-air.
    const Score kept = ScoreRun(truth, run(" --keep-frame-times", "stamped", false));
    std::printf("as stamped: %d of %d within, %d false rows\n%s", kept.within, kept.wanted, kept.false_rows,
                kept.table.c_str());
    EXPECT_TRUE(kept.within < kept.wanted || kept.false_rows > 0);
  } else {
    EXPECT_TRUE(capture.is_null()) << capture.dump();
  }
}

// Real time with long steps: a 240 fps clip whose encoder kept only every 8th picture for
// 1.75 s, each at its own time (FFmpeg's select filter, stamps passed through). The steps look
// like slow motion; the arcs' gravity against the ball's size says they were real: the stamps
// are read as they are.
TEST(VariableRate, LongStepsOfRealTimeAreReadAsStamped) {
  const auto dir = testing::ScratchDir("variable_rate_decimated");
  const auto taken = dir / "taken.mp4", kept = dir / "kept.mp4";
  std::string log;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " synth -q -o '" + taken.string() +
                                    "' --ball tennis --drop-height 0.8 --fps 240 --hold 0.2 --duration 2.8 "
                                    "--size 320x480",
                                &log),
            0)
      << log;
  ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -i '" + taken.string() +
                                    "' -vf \"select='not(between(t\\,0.45\\,2.2))+not(mod(n\\,8))'\" "
                                    "-fps_mode passthrough -c:v mpeg4 -q:v 2 '" + kept.string() + "'",
                                &log),
            0)
      << log;
  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(taken));
  const auto o = dir / "run";
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + kept.string() +
                                    "' --ball tennis --speed 0 --no-fit --lcm-url memq:// --overwrite --out '" +
                                    o.string() + "'",
                                &log),
            0)
      << log;
  const auto summary = nlohmann::json::parse(std::ifstream(o / "summary.json"));
  EXPECT_TRUE(summary["clock"]["capture_clock"].is_null()) << summary["clock"].dump();
  EXPECT_NE(summary["clock"]["slow_motion"].get<std::string>().find("real time"), std::string::npos)
      << summary["clock"].dump();
  const Score s = ScoreRun(truth, o);
  std::printf("decimated: %d of %d apexes within, %d false rows, scale %.4f\n%s", s.within, s.wanted,
              s.false_rows, s.scale_ratio, s.table.c_str());
  EXPECT_EQ(s.within, s.wanted) << s.table;
  EXPECT_EQ(s.false_rows, 0) << s.table;
  EXPECT_NEAR(s.scale_ratio, 1.0, 0.02);
}

INSTANTIATE_TEST_SUITE_P(
    Clips, VariableRate,
    ::testing::Values(
        // 240 fps, 8x slowed from 0.45 s to 2.2 s of real time: the release and the first
        // fall's start in real time, then three bounces slowed, then real time again.
        VariableClip{"tennis_slow_motion_8x",
                     "--drop-height 0.8 --fps 240 --hold 0.2 --slow-motion 8 --slow-from 0.45 --slow-to 2.2 "
                     "--duration 2.8 --size 320x480",
                     "tennis", true},
        VariableClip{"pingpong_slow_motion_4x",
                     "--drop-height 0.6 --fps 240 --hold 0.3 --slow-motion 4 --slow-from 0.2 --slow-to 1.6 "
                     "--duration 2.2 --size 320x480",
                     "pingpong", true},
        // Ramps from real time to 8x and back over 0.3 s, on a 1 ms tick (.mkv).
        VariableClip{"pingpong_ramps_8x_mkv",
                     "--drop-height 0.9 --fps 240 --hold 0.3 --slow-motion 8 --slow-from 0.2 --slow-to 2.0 "
                     "--slow-ramp 0.3 --duration 2.6 --size 320x480",
                     "pingpong", true, ".mkv"},
        // A phone's file: ramps over 0.2 s into 8x and back, stamped on a 1/600 s tick from
        // an uneven first step (the first four steps average 3.75 ms: a 300 fps guess).
        VariableClip{"tennis_phone_ticks_8x",
                     "--drop-height 0.8 --fps 240 --hold 0.2 --slow-motion 8 --slow-from 0.3 --slow-to 2.2 "
                     "--slow-ramp 0.2 --duration 2.8 --size 320x480",
                     "tennis", true, ".mp4", 600},
        // A phone's ordinary video in dim light: each frame 1/30 to 1/26 s after the last.
        VariableClip{"tennis_phone_26_30fps",
                     "--drop-height 1.0 --fps 30 --vfr-min-fps 26 --exposure 0.02 --hold 0.5 --duration 3.5 "
                     "--size 480x640",
                     "tennis", false}),
    Name);

}  // namespace
}  // namespace bouncefit
