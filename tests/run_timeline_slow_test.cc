// One timeline for every output of a run: rendered drops (the release seen, a clip begun
// mid-bounce, two drops in one clip, a 4x slow-motion file) and a real phone's slow-motion
// clip (a 2.5 m fall: the fitted drag decides when it lands) through `bouncefit run` and
// `bouncefit report`, then read back from the files a user opens. Each drop's simulated ball
// in simulated.csv starts at the apex its fit started from (peaks.csv's row of that drop and
// bounce, within a frame) and reaches its first rebound within 2 frames and max(3 mm, 5%) of
// the recorded one, on the same clock; coefficients.json pairs each fitted height with the
// peaks.csv row of its bounce; the report's bounce figure shows, per bounce, the simulated
// minus recorded height coefficients.json holds; fitted_ball.glb has the fitted and the
// recorded ball, both from the start apex on one real-seconds clock; `predict` without --drop
// drops the run's ball from there and numbers and times its bounces as peaks.csv.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "tests/gltf_playback.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;

struct Clip {
  const char* name;
  const char* ball;
  const char* synth_flags;
  bool slow_motion_4x;   // re-stamped 4x slower, tagged as a phone's slow motion
  int drops;             // drops the fit is to hold
  bool release_in_view;  // the fit starts at the release (bounce 0) of its own drop
  const char* real_clip = nullptr;  // ../shared/real-clips/<this> instead of a rendered clip
};

void PrintTo(const Clip& c, std::ostream* os) { *os << c.name; }

double Num(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto it = row.find(column);
  return it == row.end() || it->second.empty() ? NAN : std::stod(it->second);
}

// A simulated drop's first rebound apex: the highest sample between its first two impacts
// (the lowest samples before and after it).
struct Apex {
  double t_s = NAN, height_m = NAN;
};
Apex FirstRebound(const std::vector<std::pair<double, double>>& sim) {
  size_t i = 1;
  while (i < sim.size() && sim[i].second <= sim[i - 1].second) ++i;  // falling to the first impact
  Apex a;
  for (; i < sim.size() && (std::isnan(a.height_m) || sim[i].second >= sim[i - 1].second); ++i)
    if (std::isnan(a.height_m) || sim[i].second > a.height_m) a = {sim[i].first, sim[i].second};
  return a;
}

class RunTimeline : public ::testing::TestWithParam<Clip> {};

TEST_P(RunTimeline, EveryOutputStartsTheFittedBallAtItsStartApex) {
  const Clip& c = GetParam();
  const fs::path dir = testing::ScratchDir(c.name);
  std::string log;
  fs::path clip = dir / "drop.avi";
  if (c.real_clip) {
    clip = testing::RealClipsDir() / c.real_clip;
    if (!fs::exists(clip)) GTEST_SKIP() << "real clips not found (../shared/real-clips)";
  } else {
    ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " synth -q --ball " + c.ball + " " + c.synth_flags +
                                      " -o '" + clip.string() + "'",
                                  &log),
              0)
        << log;
  }
  if (c.slow_motion_4x) {  // as a phone writes it: 120 fps captured, played at 30 fps, tagged
    const fs::path slow = dir / "slomo.mov";
    if (testing::RunCommand("ffmpeg -version", &log) != 0) GTEST_SKIP() << "no ffmpeg";
    ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -itsscale 4 -i '" + clip.string() +
                                      "' -c:v copy -movflags use_metadata_tags -metadata "
                                      "com.android.capture.fps=120.000000 '" + slow.string() + "'",
                                  &log),
              0)
        << log;
    clip = slow;
  }
  const fs::path out = dir / "run";
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + clip.string() + "' --ball " + c.ball +
                                    " --speed 0 --lcm-url memq:// -q --out '" + out.string() + "'",
                                &log),
            0)
      << log;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " report '" + out.string() + "'", &log), 0) << log;

  const auto peaks = testing::ReadCsv(out / "peaks.csv");
  const auto track = testing::ReadCsv(out / "track.csv");
  const auto simulated = testing::ReadCsv(out / "simulated.csv");
  const nlohmann::json coeffs = nlohmann::json::parse(std::ifstream(out / "coefficients.json"));
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  ASSERT_FALSE(simulated.empty());
  // One frame on the run's clock (the file's stamps): the median step of track.csv.
  std::vector<double> steps;
  for (size_t i = 1; i < track.size(); ++i) steps.push_back(Num(track[i], "t_s") - Num(track[i - 1], "t_s"));
  std::nth_element(steps.begin(), steps.begin() + long(steps.size() / 2), steps.end());
  const double frame_s = steps[steps.size() / 2];
  // Real seconds per second of the run's clock: the detector's, and the one the fit measured.
  const double time_scale = summary["clock"]["time_scale"].get<double>();
  EXPECT_NEAR(coeffs["time_scale"].get<double>(), time_scale, 0.02 * time_scale);
  if (c.slow_motion_4x) {
    EXPECT_NEAR(time_scale, 0.25, 1e-6);
  }

  auto row_of = [&](int drop, int bounce) -> const std::map<std::string, std::string>* {
    for (const auto& r : peaks)
      if (int(Num(r, "bounce")) == bounce && (r.count("drop") ? int(Num(r, "drop")) : 0) == drop) return &r;
    return nullptr;
  };
  const auto& drops = coeffs["drops"];
  ASSERT_EQ(int(drops.size()), c.drops) << coeffs.dump(1);
  EXPECT_EQ(coeffs["start_bounce"].get<int>(), drops[0]["start_bounce"].get<int>());
  EXPECT_EQ(coeffs["start_bounce"].get<int>() == 0, c.release_in_view);
  std::map<std::pair<int, int>, double> fitted_difference_mm;  // (drop, bounce) -> simulated - recorded
  for (const auto& d : drops) {
    const int drop = d["drop"].get<int>(), start = d["start_bounce"].get<int>();
    const auto bounces = d["bounces"].get<std::vector<int>>();
    const auto recorded = d["recorded_m"].get<std::vector<double>>();
    const auto simulated_m = d["simulated_m"].get<std::vector<double>>();
    ASSERT_FALSE(bounces.empty());
    // Its start apex is peaks.csv's row of that drop and bounce, at its height and time.
    const auto* start_row = row_of(drop, start);
    ASSERT_NE(start_row, nullptr) << "drop " << drop << " bounce " << start;
    EXPECT_NEAR(d["start_height_m"].get<double>(), Num(*start_row, "fused_height_m"), 1e-4);
    EXPECT_NEAR(d["start_t_s"].get<double>(), Num(*start_row, "t_s"), 1e-6);
    // Each fitted height is the one of the row its bounce names: paired by number.
    for (size_t i = 0; i < bounces.size(); ++i) {
      EXPECT_EQ(bounces[i], start + 1 + int(i));
      const auto* row = row_of(drop, bounces[i]);
      ASSERT_NE(row, nullptr) << "drop " << drop << " bounce " << bounces[i];
      EXPECT_NEAR(recorded[i], Num(*row, "fused_height_m"), 1e-4) << "drop " << drop << " bounce " << bounces[i];
      fitted_difference_mm[{drop, bounces[i]}] = (simulated_m[i] - recorded[i]) * 1000;
    }

    // simulated.csv's rows of this drop: from the start apex, on peaks.csv's clock.
    std::vector<std::pair<double, double>> sim;
    for (const auto& r : simulated)
      if (int(Num(r, "drop")) == drop) sim.push_back({Num(r, "t_s"), Num(r, "height_m")});
    ASSERT_GT(sim.size(), 10u) << "drop " << drop;
    const double start_t = Num(*start_row, "t_s");
    const Apex first = FirstRebound(sim);
    const auto* rebound = row_of(drop, start + 1);
    ASSERT_NE(rebound, nullptr);
    const double rec_t = Num(*rebound, "t_s"), rec_h = Num(*rebound, "fused_height_m");
    std::printf("%s drop %d: starts at #%d: simulated from %.4f s, apex at %.4f s (%+.2f frames); first rebound "
                "#%d simulated %.4f s %.4f m, recorded %.4f s %.4f m (%+.2f frames, %+.1f mm)\n",
                c.name, drop, start, sim.front().first, start_t, (sim.front().first - start_t) / frame_s, start + 1,
                first.t_s, first.height_m, rec_t, rec_h, (first.t_s - rec_t) / frame_s,
                (first.height_m - rec_h) * 1000);
    EXPECT_LE(std::abs(sim.front().first - start_t), frame_s) << "drop " << drop;
    EXPECT_NEAR(sim.front().second, Num(*start_row, "fused_height_m"), 1e-4);
    EXPECT_LE(std::abs(first.t_s - rec_t), 2 * frame_s) << "drop " << drop;
    EXPECT_LE(std::abs(first.height_m - rec_h), std::max(0.003, 0.05 * rec_h)) << "drop " << drop;
  }

  // The report's bounce figure: per (drop, bounce), what coefficients.json holds.
  std::ifstream dat(out / "report_plots" / "bounces_difference.dat");
  ASSERT_TRUE(dat) << "no bounces_difference.dat";
  std::string line;
  size_t plotted = 0;
  while (std::getline(dat, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    double position = 0, mm = 0, sigma = 0;
    int drop = 0, bounce = 0;
    in >> position >> mm >> sigma >> drop >> bounce;
    const auto it = fitted_difference_mm.find({drop, bounce});
    ASSERT_NE(it, fitted_difference_mm.end()) << "plotted drop " << drop << " bounce " << bounce << " was not fitted";
    EXPECT_NEAR(mm, it->second, 1e-4) << "drop " << drop << " bounce " << bounce;
    ++plotted;
  }
  EXPECT_EQ(plotted, fitted_difference_mm.size());

  // predict without --drop: the run's own drop, its bounces numbered and timed as peaks.csv.
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " predict --json --members 2 --coeffs '" +
                                    (out / "coefficients.json").string() + "'",
                                &log),
            0)
      << log;
  const nlohmann::json predicted = nlohmann::json::parse(log.substr(log.find('{')));
  {
    const auto& d = drops[0];
    const int start = d["start_bounce"].get<int>();
    EXPECT_EQ(predicted["start"]["bounce"].get<int>(), start);
    EXPECT_NEAR(predicted["drop_height_m"].get<double>(), d["start_height_m"].get<double>(), 1e-9);
    ASSERT_FALSE(predicted["bounces"].empty());
    EXPECT_EQ(predicted["bounces"][0].get<int>(), start + 1);
    const auto* rebound = row_of(d["drop"].get<int>(), start + 1);
    ASSERT_NE(rebound, nullptr);
    EXPECT_LE(std::abs(predicted["single_run_apex_t_s"][0].get<double>() - Num(*rebound, "t_s")), 2 * frame_s);
    EXPECT_NEAR(predicted["single_run_heights_m"][0].get<double>(), d["simulated_m"][0].get<double>(), 1e-9);
  }

  // fitted_ball.glb: both balls from the fit's own drop's start apex, in real seconds.
  const tinygltf::Model glb = testing::LoadGlb(out / "fitted_ball.glb");
  const int fitted_node = testing::NodeNamed(glb, "fitted_ball"), recorded_node = testing::NodeNamed(glb, "recorded_ball");
  ASSERT_GE(fitted_node, 0);
  ASSERT_GE(recorded_node, 0) << "no recorded_ball: the run has a track";
  const auto& animation = glb.asset.extras.Get("animation");
  const double fitted_apex_s = animation.Get("simulated_apex_times_s").Get(0).GetNumberAsDouble();
  const auto& own = drops[0];
  const double own_start_t = own["start_t_s"].get<double>();
  const auto* own_rebound = row_of(own["drop"].get<int>(), own["start_bounce"].get<int>() + 1);
  ASSERT_NE(own_rebound, nullptr);
  const double rebound_real_s = (Num(*own_rebound, "t_s") - own_start_t) * time_scale;
  const double real_frame_s = frame_s * time_scale;
  const testing::Playback rec = testing::PlayNode(glb, recorded_node);
  ASSERT_FALSE(rec.t_s.empty());
  auto lowest = [](const std::vector<std::array<double, 3>>& v) {
    double y = 1e9;
    for (const auto& p : v) y = std::min(y, p[1]);
    return y;
  };
  // The recorded ball starts where the ball was first seen from the start apex on (a real
  // clip's release may be extrapolated, the ball not yet found there).
  double first_seen_s = NAN;
  for (const auto& r : track)
    if (Num(r, "found") == 1 && Num(r, "t_s") >= own_start_t - frame_s) {
      first_seen_s = std::max(0.0, (Num(r, "t_s") - own_start_t) * time_scale);
      break;
    }
  EXPECT_GE(rec.t_s.front(), 0.0);
  EXPECT_NEAR(rec.t_s.front(), first_seen_s, real_frame_s);
  EXPECT_NEAR(lowest(rec.vertices_m.front()), own["start_height_m"].get<double>(),
              std::max(0.01, 0.05 * own["start_height_m"].get<double>()));
  // The recorded ball's first rebound apex where peaks.csv has it, beside the fitted one's.
  double top = -1, top_t = NAN;
  for (size_t k = 0; k < rec.t_s.size(); ++k)
    if (std::abs(rec.t_s[k] - rebound_real_s) <= 3 * real_frame_s && lowest(rec.vertices_m[k]) > top)
      top = lowest(rec.vertices_m[k]), top_t = rec.t_s[k];
  EXPECT_NEAR(top, Num(*own_rebound, "fused_height_m"), std::max(0.005, 0.05 * Num(*own_rebound, "fused_height_m")));
  EXPECT_LE(std::abs(fitted_apex_s - rebound_real_s), 2 * real_frame_s)
      << "fitted apex " << fitted_apex_s << " s, recorded " << rebound_real_s << " s (recorded ball's top at "
      << top_t << " s)";
}

INSTANTIATE_TEST_SUITE_P(
    Rendered, RunTimeline,
    ::testing::Values(
        Clip{"release_seen", "pingpong", "--drop-height 0.8 --duration 2.5", false, 1, true},
        // The clip begins 0.9 s after the release: its first apex in view is a rebound.
        Clip{"mid_bounce", "tennis", "--drop-height 1.2 --start-after-release 0.9 --duration 3", false, 1, false},
        // Two drops at two distances from the camera, each fitted from its own release.
        Clip{"two_drops", "tennis",
             "--color 40,60,210 --drops 2 --drop-distances 1.6,1.1 --drop-heights 0.8,0.6 --size 360x640 --fps 60 "
             "--exposure 0.004",
             false, 2, true},
        Clip{"slow_motion_4x", "tennis", "--drop-height 1.0 --fps 120 --duration 2.4", true, 1, true}),
    [](const ::testing::TestParamInfo<Clip>& clip) { return std::string(clip.param.name); });

INSTANTIATE_TEST_SUITE_P(
    Real, RunTimeline,
    ::testing::Values(
        // A phone's slow motion, captured at 120 fps, stored at 30 fps and tagged: a 4 cm ball
        // heavier than a ping-pong ball falls 2.5 m from the ceiling.
        Clip{"red_ball_slow_motion", "pingpong", "", false, 1, true, "red_ball_ceiling_drop_slomo120_30fps.mp4"}),
    [](const ::testing::TestParamInfo<Clip>& clip) { return std::string(clip.param.name); });

}  // namespace
}  // namespace bouncefit
