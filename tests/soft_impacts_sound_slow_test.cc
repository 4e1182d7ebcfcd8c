// Soft impacts in room noise, end to end: balls dropped from low (most impacts slow, their
// clicks quiet) over white room noise at -44 dBFS, or at -48 dBFS with voices, with or
// without mains hum; `bouncefit synth` then `bouncefit run`. Of the impacts at 0.5 m/s or faster, at
// least 95% are heard (impacts.csv rows "audio" or "both" within 20 ms), and no heard row
// is an impact that did not happen.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

struct Tally {
  int fast = 0, heard = 0, invented = 0;
};

void RunAndScore(const std::string& name, const std::string& ball, double drop_m, double seconds,
                 const std::string& sound, int seed, Tally* tally) {
  const auto dir = testing::ScratchDir(name);
  const auto clip = dir / "clip.avi";
  std::string out;
  const std::string synth = testing::BouncefitExe() + " synth -q --fps 60 --size 320x240 --ball " +
                            ball + " --drop-height " + std::to_string(drop_m) + " --duration " +
                            std::to_string(seconds) + " --seed " + std::to_string(seed) +
                            " --sound " + sound + " --out " + clip.string();
  ASSERT_EQ(testing::RunCommand(synth, &out), 0) << out;
  const SynthTruth t = LoadSynthTruth(SynthTruthPathFor(clip));
  const std::string run = testing::BouncefitExe() + " run " + clip.string() + " --ball " + ball +
                          " --no-fit --speed 0 -q --lcm-url memq:// --out " + (dir / "run").string();
  ASSERT_EQ(testing::RunCommand(run, &out), 0) << out;
  std::vector<double> heard;
  for (const auto& r : testing::ReadCsv(dir / "run" / "impacts.csv"))
    if (r.at("source") != "video") heard.push_back(std::stod(r.at("t_s")));
  const auto near = [](double a, double b) { return std::abs(a - b) <= 0.02; };
  for (size_t k = 0; k < t.impact_times_s.size(); ++k) {
    if (t.impact_speeds_mps[k] < 0.5 || t.impact_times_s[k] > seconds - 0.05) continue;
    ++tally->fast;
    bool found = false;
    for (double h : heard) found = found || near(h, t.impact_times_s[k]);
    tally->heard += found;
    if (!found)
      std::printf("  %s: not heard: the impact at %.3f s, %.2f m/s\n", name.c_str(), t.impact_times_s[k],
                  t.impact_speeds_mps[k]);
  }
  for (double h : heard) {
    bool real = false;
    for (double ti : t.impact_times_s) real = real || near(h, ti);
    tally->invented += !real;
    if (!real) std::printf("  %s: heard at %.3f s, no impact there\n", name.c_str(), h);
  }
}

TEST(SoftImpactsSound, NinetyFivePercentHeardAtHalfAMetrePerSecondAndNothingInvented) {
  const struct {
    const char* name;
    const char* sound;
  } rooms[] = {{"noisy", "--room-noise 0.006"},
               {"voices", "--room-noise 0.004 --chatter"},
               {"voices_hum", "--room-noise 0.004 --chatter --hum"}};
  Tally all;
  for (const auto& room : rooms) {
    Tally t;
    for (int seed : {1, 2}) {
      // A ping-pong ball from 0.5 m: impacts of 0.5 m/s and more end near 5.2 s.
      RunAndScore(std::string(room.name) + "_pingpong_" + std::to_string(seed), "pingpong", 0.5, 5.5,
                  room.sound, seed, &t);
      // A tennis ball from 0.4 m: near 2.3 s.
      RunAndScore(std::string(room.name) + "_tennis_" + std::to_string(seed), "tennis", 0.4, 3.0,
                  room.sound, seed, &t);
    }
    std::printf("%-10s %d of %d impacts >= 0.5 m/s heard (%.1f%%), %d invented\n", room.name, t.heard,
                t.fast, 100.0 * t.heard / std::max(t.fast, 1), t.invented);
    EXPECT_GE(t.heard, 0.95 * t.fast) << room.name;
    all.fast += t.fast, all.heard += t.heard, all.invented += t.invented;
  }
  EXPECT_GE(all.fast, 80);  // the clips hold the slow impacts this is about
  EXPECT_GE(all.heard, 0.95 * all.fast);
  EXPECT_EQ(all.invented, 0);
}

}  // namespace
}  // namespace bouncefit
