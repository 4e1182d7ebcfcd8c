// The bounce detector on whole clips. On `bouncefit synth` clips with known truth, for all four
// presets from 1.0 m and 1.6 m at 120 fps and a 60 fps clip, with camera roll up to 2 degrees:
//  (a) on the synth truth centres plus tracker-like noise (the detector alone),
//  (b) on what the tracker finds in the rendered video (the real pipeline);
// every apex above 1 cm found, no false peaks, heights within max(2 mm, 1%) using the
// detector's own calibration, latency median <= 2 and max <= 4 frames. Then a real clip, a
// phone's slow-motion file, a file that shows each picture twice, and the `detect` command as
// a process of its own over UDP multicast, fed by this process.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <thread>

#include <nlohmann/json.hpp>

#include "msgs/lcm_bus.h"
#include "synth/synth_truth.h"
#include "tests/detect_sim.h"
#include "tests/test_support.h"
#include "tests/tracker_test_util.h"
#include "pipeline/message_mapping.h"

namespace bouncefit {
namespace {

struct Case {
  std::string ball;
  double drop_m;
  double fps;
  double roll_deg;
  // Motion kinds beyond a drop from rest: a throw, a clip that begins after the
  // release (mid-bounce), a long exposure (motion blur); the name says which.
  std::string kind = "";
  double throw_up_mps = 0, throw_right_mps = 0, start_s = 0, exposure_s = 0;
  double px_per_m = 0, ball_x = 0.5;
};

std::string Name(const Case& c) {
  return fmt::format("{}_{:02.0f}dm_{:.0f}fps{}{}", c.ball, c.drop_m * 10, c.fps, c.kind.empty() ? "" : "_", c.kind);
}

// Renders the clip (once per test binary run) and returns its path.
std::filesystem::path Render(const Case& c) {
  const auto dir = testing::ScratchDir("detect_slow_" + Name(c));
  const auto clip = dir / "clip.avi";
  // Long enough for every apex above 1 cm.
  PointMassDropConfig pc;
  pc.ball = ResolveBallPreset(c.ball);
  pc.drop_height_m = c.drop_m;
  pc.hold_s = c.start_s > 0 ? 0.0 : 0.5;
  pc.launch_speed_mps = c.throw_up_mps;
  const auto r = SimulatePointMassDrop(pc);
  double end = 1.5;
  for (size_t b = 0; b < r.apex_heights_m.size(); ++b)
    if (r.apex_heights_m[b] > 0.01 && b < r.impact_times_s.size()) end = r.impact_times_s[b] + 0.4;
  end -= c.start_s;
  const std::string cmd = fmt::format(
      "{} synth -o '{}' --ball {} --drop-height {:g} --fps {:g} --roll {:g} --duration {:.2f} "
      "--throw-up {:g} --throw-right {:g} --start-after-release {:g} --exposure {:g} "
      "--px-per-m {:g} --ball-x {:g} --quiet",
      testing::BouncefitExe(), clip.string(), c.ball, c.drop_m, c.fps, c.roll_deg, end, c.throw_up_mps,
      c.throw_right_mps, c.start_s, c.exposure_s > 0 ? c.exposure_s : 0.004, c.px_per_m, c.ball_x);
  std::string out;
  if (testing::RunCommand(cmd, &out) != 0) throw std::runtime_error("synth failed: " + out);
  return clip;
}

testing::TruthApexes TruthOf(const SynthTruth& t) {
  testing::TruthApexes a;
  a.fps = t.fps;
  a.apex_t_s = t.apex_times_s;
  a.apex_h_m = t.apex_heights_m;
  a.impact_t_s = t.impact_times_s;
  if (t.release_t_s < 0) {
    // Begun after the release: the detector counts the first apex it sees after an impact
    // it did not see as bounce 1 (it cannot know how many came before).
    a.apex_t_s.insert(a.apex_t_s.begin(), -100.0);
    a.apex_h_m.insert(a.apex_h_m.begin(), 0.0);
  }
  return a;
}

struct Outcome {
  testing::PeakScore score;
  double cal_err_pct = 0, roll_err_deg = 0;
};

Outcome Detect(const std::vector<BallObservation>& obs, const SynthTruth& truth) {
  BounceDetector d{BounceDetectorConfig{}};
  const auto peaks = testing::RunDetector(d, obs);
  Outcome o;
  // Required: apexes of 1 cm or more whose flight lasts 4 frames or more (the detector
  // reports no shorter hop); the arc a clip begins with waits for the floor (first impact),
  // like a release height, so it is left out of the latency.
  const double t4 = 4 / truth.fps;
  o.score = testing::ScorePeaks(TruthOf(truth), peaks, std::max(0.01, 9.81 * t4 * t4 / 8));
  if (truth.release_t_s < 0 && !o.score.latency_frames.empty())
    o.score.latency_frames.erase(o.score.latency_frames.begin());
  o.cal_err_pct = (d.calibration().px_per_m / truth.px_per_m - 1) * 100;
  o.roll_err_deg = d.calibration().roll_rad * 180 / M_PI - truth.roll_deg;
  return o;
}

void Check(const std::string& what, const Case& c, const Outcome& o) {
  const auto& s = o.score;
  const double med = testing::Median(s.latency_frames), mx = testing::MaxOf(s.latency_frames);
  // One line per clip: the figures of docs/ACCURACY.md.
  std::printf("| %s | %s | %.1f | %.0f | %.1f | %d/%d | %d | %.2f | %+.3f | %.1f | %.1f | %.1f |\n",
              what.c_str(), c.ball.c_str(), c.drop_m, c.fps, c.roll_deg, s.found_over_1cm,
              s.truth_over_1cm, s.false_peaks, s.max_err_mm, o.cal_err_pct, med, mx,
              s.bounce0_latency_from_impact_frames);
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << what << "\n" << s.report;
  EXPECT_EQ(s.false_peaks, 0) << what << "\n" << s.report;
  EXPECT_TRUE(s.within_tolerance) << what << "\n" << s.report;
  EXPECT_LE(med, 2.0) << what << "\n" << s.report;
  EXPECT_LE(mx, 4.0) << what << "\n" << s.report;
  EXPECT_LT(std::abs(o.roll_err_deg), 0.3) << what;
}

class DetectSynth : public ::testing::TestWithParam<Case> {};

TEST_P(DetectSynth, TruthCentresWithNoiseAndTrackerOutput) {
  const Case c = GetParam();
  const auto clip = Render(c);
  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(clip));

  // (a) truth centres + noise like the tracker's (0.2 px), ball found whenever in view.
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.2);
  std::vector<BallObservation> synthetic;
  for (const auto& f : truth.frames) {
    BallObservation o;
    o.frame = f.index;
    o.utime = std::llround(f.t_s * 1e6);
    o.found = f.fully_in_view;
    if (o.found) {
      o.cx = static_cast<float>(f.cx + noise(rng));
      o.cy = static_cast<float>(f.cy + noise(rng));
      o.radius_px = static_cast<float>(truth.radius_px);
      o.w = o.h = 2 * o.radius_px;
    }
    synthetic.push_back(o);
  }
  Check("truth+noise", c, Detect(synthetic, truth));

  // (b) the tracker on the rendered video.
  const auto tracked = testing::TrackClip(
      clip, testing::ConfigForColor(truth.ball_color_bgr, truth.ball), &truth);
  std::printf("tracker: rms %.3f px, lost %d of %d in view\n", tracked.rms, tracked.lost,
              tracked.in_view);
  Check("tracker", c, Detect(tracked.obs, truth));
}

INSTANTIATE_TEST_SUITE_P(
    AllPresets, DetectSynth,
    ::testing::Values(Case{"pingpong", 1.0, 120, 2}, Case{"pingpong", 1.6, 120, -1},
                      Case{"wiffle", 1.0, 120, 0}, Case{"wiffle", 1.6, 120, 2},
                      Case{"softball", 1.0, 120, -2}, Case{"softball", 1.6, 120, 1},
                      Case{"airball", 1.0, 120, 1}, Case{"airball", 1.6, 120, 0},
                      Case{"airball", 1.6, 60, 2},
                      // Thrown up and sideways from the hand: the throw's top is bounce 0.
                      Case{"tennis", 0.8, 60, 1, "thrown", 1.5, 0.15, 0, 0, 380, 0.3},
                      // Already bouncing: the clip begins on the first rebound's rise.
                      Case{"tennis", 1.0, 60, 0, "midbounce", 0, 0, 0.6},
                      // 30 fps with a 1/60 s exposure: the ball smears over its size.
                      Case{"tennis", 1.0, 30, 1, "blur", 0, 0, 0, 1.0 / 60}),
    [](const ::testing::TestParamInfo<Case>& i) { return Name(i.param); });

// Real footage has no truth. The tennis clip has a ruler (its author used 253.7 px/m) and a
// ball of known size; its free fall says 305 px/m, 20% more, while the ball's size agrees
// with the ruler: the clip's 25 fps clock is not the camera's (a wrong frame clock is a known source of
// 20% errors in g in video analysis). What must hold on real footage whatever the clock: the heights in
// metres agree with the scale-free flight-time heights g dt^2/8 (both scale alike with a
// wrong clock), and the diameter cross-check exposes the inconsistency.
TEST(DetectRealClips, TennisHeightsAgreeWithFlightTimes) {
  const auto dir = testing::RealClipsDir();
  if (dir.empty() || !std::filesystem::exists(dir / "tennis_ruler_25fps.mp4"))
    GTEST_SKIP() << "real clips not found (../shared/real-clips)";
  const auto tracked = testing::TrackClip(dir / "tennis_ruler_25fps.mp4", TrackerConfig{}, nullptr);
  BounceDetectorConfig cfg;
  cfg.calibration.ball_diameter_m = 0.067;  // ITF tennis ball
  BounceDetector d{cfg};
  const auto peaks = testing::RunDetector(d, tracked.obs);
  const Calibration& c = d.calibration();
  std::printf("tennis: %s; %.1f +- %.1f px/m (ruler 253.7), roll %.2f deg, radius %.2f px, "
              "diameter ratio %.3f, %zu peaks:",
              tracked.describe.c_str(), c.px_per_m, c.px_per_m_sigma, c.roll_rad * 180 / M_PI,
              c.radius_px, c.diameter_ratio, peaks.size());
  for (const auto& p : peaks) std::printf(" %d:%.3f m", p.bounce, p.height_m);
  std::printf("\n");
  for (const auto& sum : d.Summaries())
    for (size_t b = 0; b < sum.flight_height_m.size(); ++b)
      std::printf("  bounce %zu: %.3f m, flight time %.3f m\n", b, sum.final_height_m[b],
                  sum.flight_height_m[b]);
  ASSERT_TRUE(d.calibrated());
  EXPECT_GE(peaks.size(), 5u);
  ASSERT_FALSE(d.Summaries().empty());
  const auto& sum = d.Summaries()[0];
  int compared = 0;
  for (size_t b = 1; b < sum.flight_height_m.size(); ++b) {
    if (!(sum.final_height_m[b] >= 0.1) || !std::isfinite(sum.flight_height_m[b])) continue;
    EXPECT_NEAR(sum.flight_height_m[b], sum.final_height_m[b], 0.03 * sum.final_height_m[b]) << b;
    ++compared;
  }
  EXPECT_GE(compared, 3);
  EXPECT_LT(c.diameter_ratio, 0.9);  // the clock is off: the ball looks too small for G
}

// `bouncefit detect` as a process of its own: boxes published from here over UDP multicast
// (ttl=0), peaks printed by it, and it exits by itself after --exit-after-idle.
// The clock: a phone's slow-motion file holds frames captured at 120 fps on a
// 30 fps timeline and says so in its metadata (com.android.capture.fps). Made here from a
// synth clip by stretching its timestamps 4x (ffmpeg -itsscale, no re-encoding). Gravity
// read on that clock is 16x too small; the ball's size says so; with the container's word
// the run switches to real time and the heights match the truth. Without the tag (a slow-motion
// file re-encoded) a 16x disagreement, more than any ball given with the wrong preset makes
// (their diameters span 6x), is taken for 4x slow motion too, and the run says the file did
// not, with the same heights; --time-scale forces either clock; a ball given with the wrong
// size is never taken for slow motion, unless the container says so and the size is nearer
// its clock than the recorded one, within 2x (a ball given as the nearest preset).
TEST(DetectClock, SlowMotionFromTheContainerConfirmedByTheBallSize) {
  const auto dir = testing::ScratchDir("detect_clock");
  const auto clip = dir / "clip.avi";
  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " synth -o '" + clip.string() +
                                    "' --ball tennis --drop-height 1.0 --fps 120 --duration 2.4 "
                                    "--quiet",
                                &out),
            0)
      << out;
  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(clip));
  const auto tagged = dir / "slomo.mov", plain = dir / "slomo_notag.mov";
  ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -itsscale 4 -i '" + clip.string() +
                                    "' -c:v copy -movflags use_metadata_tags -metadata "
                                    "com.android.capture.fps=120.000000 '" + tagged.string() + "'",
                                &out),
            0)
      << out;
  ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -itsscale 4 -i '" + clip.string() +
                                    "' -c:v copy '" + plain.string() + "'",
                                &out),
            0)
      << out;
  auto run = [&](const std::filesystem::path& file, const std::string& flags,
                 const std::string& tag, std::string* log) {
    const auto o = dir / tag;
    EXPECT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + file.string() + "' " +
                                      flags + " --speed 0 --no-fit --lcm-url memq:// --out '" +
                                      o.string() + "'",
                                  log),
              0)
        << *log;
    return nlohmann::json::parse(std::ifstream(o / "summary.json"));
  };
  auto expect_truth_heights = [&](const nlohmann::json& s, const std::string& log) {
    int matched = 0;
    for (const auto& p : s["peaks"]) {
      const auto b = p["bounce"].get<size_t>();
      if (b >= truth.apex_heights_m.size()) continue;
      const double h = truth.apex_heights_m[b];
      EXPECT_NEAR(p["height_m"].get<double>(), h, std::max(0.002, 0.01 * h)) << b << log;
      ++matched;
    }
    EXPECT_GE(matched, 3) << log;
  };

  std::string log;
  const auto slow = run(tagged, "--ball tennis", "tagged", &log);
  EXPECT_DOUBLE_EQ(slow["clock"]["time_scale"].get<double>(), 0.25) << log;
  EXPECT_NE(log.find("slow motion"), std::string::npos) << log;
  expect_truth_heights(slow, log);

  const auto untagged = run(plain, "--ball tennis", "plain", &log);
  EXPECT_DOUBLE_EQ(untagged["clock"]["time_scale"].get<double>(), 0.25) << log;
  EXPECT_NE(log.find("the file does not say so"), std::string::npos) << log;
  // Every apex at its true height, the release included, numbered as the truth: the fall,
  // bending 16x less than the size's g in the file's seconds, is an arc all the same, since
  // it bends at g / 4^2 (before, it was none until the clock was decided at the first impact,
  // and the first rebound, seen from its apex, started the drop as its release).
  expect_truth_heights(untagged, log);
  EXPECT_EQ(untagged["peaks"][0]["bounce"].get<int>(), 0) << log;

  const auto forced = run(plain, "--ball tennis --time-scale 0.25", "forced", &log);
  EXPECT_DOUBLE_EQ(forced["clock"]["time_scale"].get<double>(), 0.25) << log;
  EXPECT_EQ(log.find("the file does not say so"), std::string::npos) << "the user said so\n" << log;
  expect_truth_heights(forced, log);

  // Read as recorded: the free fall and the ball's size both contradict that clock (16x), a
  // bad flag unless insisted on; then it says what a 4x slower timeline would explain.
  EXPECT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + plain.string() +
                                    "' --ball tennis --time-scale 1 --speed 0 --no-fit --lcm-url memq:// --out '" +
                                    (dir / "contradicted").string() + "'",
                                &log),
            2)
      << log;
  EXPECT_NE(log.find("--time-scale 1 (gravity's scale"), std::string::npos) << log;
  const auto as_recorded = run(plain, "--ball tennis --time-scale 1 --force", "as_recorded", &log);
  EXPECT_DOUBLE_EQ(as_recorded["clock"]["time_scale"].get<double>(), 1.0) << log;
  const auto at = log.find("slowed ");
  ASSERT_NE(at, std::string::npos) << log;
  EXPECT_NEAR(std::stod(log.substr(at + 7)), 4.0, 0.1) << log;

  // A ball given 1.7x too small (a ping-pong ball's size for a tennis ball) on the untagged
  // file: gravity and size disagree 27x, which neither a 4x nor an 8x slow-down explains.
  const auto small = run(plain, "--ball pingpong", "small_ball", &log);
  EXPECT_DOUBLE_EQ(small["clock"]["time_scale"].get<double>(), 1.0) << log;
  EXPECT_EQ(log.find("slow motion"), std::string::npos) << log;

  // The same ball on the tagged file: the container says 4x and the size, 1.7x off, agrees
  // with that clock far better than with the recorded one (27x). Real time, the heights from
  // the free fall's scale (true), and the run says the ball is not the size given.
  const auto nearest = run(tagged, "--ball pingpong", "nearest_preset", &log);
  EXPECT_DOUBLE_EQ(nearest["clock"]["time_scale"].get<double>(), 0.25) << log;
  EXPECT_NE(log.find("another ball than the preset"), std::string::npos) << log;
  expect_truth_heights(nearest, log);

  // A basketball's size for a tennis ball: gravity and size disagree by no slow-down factor.
  const auto wrong = run(tagged, "--ball basketball", "wrong_ball", &log);
  EXPECT_DOUBLE_EQ(wrong["clock"]["time_scale"].get<double>(), 1.0) << log;
  EXPECT_EQ(log.find("slow motion"), std::string::npos) << log;
}

// A file that shows each picture twice (30 fps content on a 60 fps timeline, as phones'
// variable-rate encoders and frame-rate conversions write it): made here from a 30 fps synth
// clip with ffmpeg's fps filter. Each picture is tracked once, at the time it was first shown,
// so the arcs are the 30 fps clip's and every apex is found as on it.
TEST(DetectRepeatedFrames, ThirtyFpsPicturesOnASixtyFpsTimeline) {
  const auto dir = testing::ScratchDir("detect_repeated_frames");
  const auto clip = dir / "clip30.avi", doubled = dir / "clip60.avi";
  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " synth -o '" + clip.string() +
                                    "' --ball tennis --drop-height 1.0 --fps 30 --duration 3 --quiet",
                                &out),
            0)
      << out;
  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(clip));
  ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -i '" + clip.string() +
                                    "' -vf fps=60 -c:v mjpeg -q:v 2 '" + doubled.string() + "'",
                                &out),
            0)
      << out;
  const auto o = dir / "out";
  ASSERT_EQ(testing::RunCommand(testing::BouncefitExe() + " run '" + doubled.string() +
                                    "' --ball tennis --speed 0 --no-fit --lcm-url memq:// --out '" +
                                    o.string() + "'",
                                &out),
            0)
      << out;
  const auto s = nlohmann::json::parse(std::ifstream(o / "summary.json"));
  const int frames = s["frames"].get<int>(), repeats = s["repeated_frames"].get<int>();
  std::printf("60 fps file of 30 fps pictures: %d delivered, %d repeats skipped\n", frames, repeats);
  // Every other picture, but for the few shown before the pattern is established (a file's
  // first repeats, and repeats while the scene is still and noise-free, are delivered).
  EXPECT_LE(repeats, frames) << out;
  EXPECT_GE(repeats, frames - 8) << out;
  EXPECT_NE(out.find("repeat the one before"), std::string::npos) << out;
  int matched = 0;
  for (const auto& p : s["peaks"]) {
    const auto b = p["bounce"].get<size_t>();
    if (b >= truth.apex_heights_m.size()) continue;
    const double h = truth.apex_heights_m[b];
    std::printf("  bounce %zu: %.4f m, truth %.4f m\n", b, p["height_m"].get<double>(), h);
    EXPECT_NEAR(p["height_m"].get<double>(), h, std::max(0.002, 0.01 * h)) << b << out;
    ++matched;
  }
  EXPECT_GE(matched, 3) << out;
}

TEST(DetectCommand, SeparateProcessPrintsThePeaks) {
  testing::SimOptions o;
  o.ball = "wiffle";
  o.drop_m = 1.3;
  const auto clip = testing::MakeSimClip(o);
  BounceDetector core{BounceDetectorConfig{}};
  const auto expected = testing::RunDetector(core, clip.obs);
  ASSERT_GE(expected.size(), 3u);

  const std::string url = testing::UniqueUdpmUrl();
  std::string out;
  int rc = -1;
  std::thread child([&] {
    rc = testing::RunCommand(testing::BouncefitExe() + " detect --lcm-url '" + url +
                                 "' --ball wiffle --exit-after-idle 1.5",
                             &out);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // let it subscribe
  {
    LcmBus bus(url);
    for (const auto& b : clip.obs) {
      bus.Publish("BALL_BOX", ToBallBox(b));
      std::this_thread::sleep_for(std::chrono::microseconds(300));
    }
  }
  child.join();
  EXPECT_EQ(rc, 0) << out;
  for (const auto& p : expected) {  // each bounce once, as `run` prints it
    const std::string line = fmt::format("peak  #{:<2}", p.bounce);
    const std::string height = fmt::format("height {:.4f} m", p.height_m);
    const size_t at = out.find(line);
    ASSERT_NE(at, std::string::npos) << line << "\n" << out;
    EXPECT_LT(out.find(height, at), out.find("\n", at)) << height << "\n" << out;
  }
  EXPECT_NE(out.find("0 undecodable"), std::string::npos) << out;
}

}  // namespace
}  // namespace bouncefit
