// Pictures taken at one rate and kept at a lower one (a frame-rate conversion that drops some,
// each kept picture stamped on the lower rate's grid): rendered drops with known truth, taken
// at 24-60 fps and converted by FFmpeg's fps filter (which keeps the picture nearest each
// slot, another phase than detect/frame_retiming's floor), then `bouncefit run` with nothing
// but the ball. The run finds the rate they were taken at, says so, and reads each picture at
// its own time: every apex within max(2 mm, 1%) of the truth, and all of those whose flight
// spans 6 pictures of the file found. With --keep-frame-times the stamps give broken or shifted rows.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "report/report_run_data.h"
#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

struct Conversion {
  const char* ball;
  double taken_fps, stamped_fps;
};

class RetimedClip : public ::testing::TestWithParam<Conversion> {};

std::string Name(const ::testing::TestParamInfo<Conversion>& info) {
  return fmt::format("{}_{:g}fps_stamped_{:g}fps", info.param.ball, info.param.taken_fps, info.param.stamped_fps);
}

TEST_P(RetimedClip, EveryApexOnTheClockThePicturesWereTakenOn) {
  const Conversion c = GetParam();
  const auto dir = testing::ScratchDir("retimed_clip_" + Name({c, 0}));
  const auto taken = dir / "taken.avi", stamped = dir / "stamped.avi";
  std::string out;
  // A camera's exposure: 1/50 s, or most of the frame where that is shorter.
  const double exposure_s = std::min(0.02, 0.9 / c.taken_fps);
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " synth -o '" + taken.string() + "' --ball " + c.ball +
                                    " --fps " + std::to_string(c.taken_fps) + " --exposure " +
                                    std::to_string(exposure_s) + " --size 480x640 --duration 3.5 --quiet",
                                &out),
            0)
      << out;
  ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -i '" + taken.string() + "' -vf fps=" +
                                    std::to_string(c.stamped_fps) + " -c:v mjpeg -q:v 3 '" + stamped.string() + "'",
                                &out),
            0)
      << out;
  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(taken));
  auto run = [&](const std::string& flags, const std::string& tag) {
    const auto o = dir / tag;
    std::string log;
    EXPECT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + stamped.string() + "' --ball " + c.ball +
                                      flags + " --speed 0 --no-fit --lcm-url memq:// --out '" + o.string() + "'",
                                  &log),
              0)
        << log;
    return nlohmann::json::parse(std::ifstream(o / "summary.json"));
  };
  // Rows against the truth: matched within max(2 mm, 1%), or off.
  auto score = [&](const nlohmann::json& s, int* within, int* off, std::string* table) {
    *within = *off = 0;
    for (const auto& p : s["peaks"]) {
      const auto b = p["bounce"].get<size_t>();
      const double h = p["height_m"].get<double>();
      const double want = b < truth.apex_heights_m.size() ? truth.apex_heights_m[b] : 0;
      const bool ok = std::abs(h - want) <= std::max(0.002, 0.01 * want);
      *(ok ? within : off) += 1;
      *table += fmt::format("  bounce {}: {:.4f} m (truth {:.4f}){}\n", b, h, want, ok ? "" : " OFF");
    }
  };
  // Every apex whose flight spans 6 pictures of the file at least, and ends in the clip, must
  // be found.
  const double six_pictures_m = 9.81 * std::pow(6 / c.stamped_fps, 2) / 8;
  const double clip_end_s = truth.frames.empty() ? 0 : truth.frames.back().t_s;
  int resolvable = 0;
  for (size_t k = 0; k < truth.apex_heights_m.size(); ++k) {
    const double h = truth.apex_heights_m[k];
    resolvable += h >= six_pictures_m && truth.apex_times_s[k] + std::sqrt(2 * h / 9.81) < clip_end_s;
  }

  const auto s = run("", "default");
  const std::string verdict = s["clock"]["frame_times"].get<std::string>();
  const std::string taken_at = fmt::format("frames re-timed: taken at {:g} fps", c.taken_fps);
  EXPECT_NE(verdict.find(taken_at), std::string::npos) << verdict;
  int within = 0, off = 0;
  std::string table;
  score(s, &within, &off, &table);
  std::printf("%s\n%s", verdict.c_str(), table.c_str());
  EXPECT_EQ(off, 0) << table;
  EXPECT_GE(within, resolvable) << six_pictures_m << " m and over\n" << table;

  // `report` reads the track on the rows' clock: every picture where the ball was, at the time
  // it was taken (a tick of the capture rate), and its centre where the truth puts it then, up
  // to one constant tick (a shift of the whole clock no motion shows: the fps filter keeps the
  // picture after each slot, the re-timing's phase may name the one before).
  const ReportRunData report = LoadRunDirectory(dir / "default");
  int found = 0, best = 0;
  for (const int shift : {-1, 0, 1}) {
    int on_truth = 0;
    found = 0;
    for (const auto& row : report.track) {
      if (!row.found) continue;
      ++found;
      const double ticks = row.t_s * c.taken_fps;
      const long n = std::lround(ticks) + shift;
      if (std::abs(ticks - std::round(ticks)) > 1e-3 * c.taken_fps || n < 0 ||
          n >= static_cast<long>(truth.frames.size()))
        continue;
      on_truth += std::abs(row.cy_px - truth.frames[static_cast<size_t>(n)].cy) < 3;
    }
    best = std::max(best, on_truth);
  }
  EXPECT_GE(best, 0.9 * found) << best << " of " << found << " tracked pictures where the truth is";

  const auto kept = run(" --keep-frame-times", "stamped");
  int kept_within = 0, kept_off = 0;
  std::string kept_table;
  score(kept, &kept_within, &kept_off, &kept_table);
  std::printf("as stamped (--keep-frame-times):\n%s", kept_table.c_str());
  EXPECT_TRUE(kept_off > 0 || kept_within < within) << "the stamps alone do as well?\n" << kept_table;
}

// A phone's 24, 25 and 60 fps, a 48 fps camera; kept at 20, 25 and 30 fps.
INSTANTIATE_TEST_SUITE_P(Conversions, RetimedClip,
                         ::testing::Values(Conversion{"tennis", 24, 20}, Conversion{"basketball", 25, 20},
                                           Conversion{"pingpong", 60, 25}, Conversion{"tennis", 48, 30}),
                         Name);

}  // namespace
}  // namespace bouncefit
