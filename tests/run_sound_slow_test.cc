// `bouncefit run` with sound, end to end: synth clips with clicks at known impact times
// (clean; chatter + hum + a 30 ms offset; 30 fps) and the shared real clips.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/impact_t.hpp"
#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::ReadCsv;
using testing::RunCommand;
using testing::ScratchDir;


double CellNumber(const std::map<std::string, std::string>& row, const std::string& col) {
  const auto it = row.find(col);
  return it == row.end() || it->second.empty() ? NAN : std::stod(it->second);
}

SynthTruth Synth(const std::filesystem::path& dir, const std::string& flags) {
  std::string out;
  const auto clip = dir / "clip.avi";
  const int rc = RunCommand(BouncefitExe() + " synth -q --duration 4.5 --size 320x240 " + flags +
                                " --out " + clip.string(), &out);
  EXPECT_EQ(rc, 0) << out;
  return LoadSynthTruth(SynthTruthPathFor(clip));
}

std::filesystem::path RunClip(const std::filesystem::path& clip, const std::string& flags,
                             const std::filesystem::path& out_dir) {
  std::string out;
  const int rc = RunCommand(BouncefitExe() + " run " + clip.string() + " --no-fit --speed 0 -q " +
                                "--lcm-url memq:// --out " + out_dir.string() + " " + flags, &out);
  EXPECT_EQ(rc, 0) << out;
  return out_dir;
}

// Every impact faster than 0.5 m/s is listed as heard within tol of the truth (video clock);
// every heard row matches a truth impact. Returns the largest error.
double CheckHeard(const SynthTruth& t, const std::filesystem::path& run, double tol) {
  const auto rows = ReadCsv(run / "impacts.csv");
  double worst = 0;
  for (size_t k = 0; k < t.impact_times_s.size(); ++k) {
    if (t.impact_speeds_mps[k] <= 0.5 || t.impact_times_s[k] + t.sound_offset_s > 4.45) continue;
    bool heard = false;
    for (const auto& r : rows)
      if (r.at("source") != "video" && std::abs(CellNumber(r, "t_s") - t.impact_times_s[k]) < tol) {
        heard = true;
        worst = std::max(worst, std::abs(CellNumber(r, "t_s") - t.impact_times_s[k]));
      }
    EXPECT_TRUE(heard) << "impact at " << t.impact_times_s[k] << " s ("
                       << t.impact_speeds_mps[k] << " m/s) not heard";
  }
  for (const auto& r : rows) {
    if (r.at("source") == "video") continue;
    bool real = false;
    for (double ti : t.impact_times_s) real = real || std::abs(CellNumber(r, "t_s") - ti) < tol;
    EXPECT_TRUE(real) << "invented impact at " << r.at("t_s") << " s";
  }
  return worst;
}

TEST(RunSound, CleanSoundTimesAndFlightHeights) {
  const auto dir = ScratchDir("clean");
  const SynthTruth t = Synth(dir, "--sound --fps 60 --ball tennis");
  const auto run = RunClip(dir / "clip.avi", "--ball tennis", dir / "run");
  EXPECT_LT(CheckHeard(t, run, 0.0003), 0.0003);
  // Flight-time heights of every bounce of 2 cm or more within 0.5%.
  int checked = 0;
  for (const auto& r : ReadCsv(run / "impacts.csv")) {
    const double h = CellNumber(r, "flight_height_m");
    if (!std::isfinite(h)) continue;
    const double t0 = CellNumber(r, "t_s");
    for (size_t k = 0; k + 1 < t.impact_times_s.size(); ++k)
      if (std::abs(t.impact_times_s[k] - t0) < 0.001 && k + 1 < t.apex_heights_m.size() &&
          t.apex_heights_m[k + 1] >= 0.02) {
        EXPECT_NEAR(h, t.apex_heights_m[k + 1], 0.005 * t.apex_heights_m[k + 1]) << "bounce " << k + 1;
        ++checked;
      }
  }
  EXPECT_GE(checked, 5);
}

TEST(RunSound, ChatterHumAndOffsetNoneMissedNoneInvented) {
  const auto dir = ScratchDir("noisy");
  const SynthTruth t = Synth(dir, "--chatter --hum --sound-offset 0.03 --fps 60 --seed 5");
  const auto run = RunClip(dir / "clip.avi", "", dir / "run");
  EXPECT_LT(CheckHeard(t, run, 0.002), 0.002);
  std::ifstream summary(run / "summary.json");
  const std::string text((std::istreambuf_iterator<char>(summary)), {});
  EXPECT_NE(text.find("sound lags the picture by 30"), std::string::npos);
}

// Apex heights at 30 fps: with sound within max(2 mm, 1%) and closer than without. The
// ping-pong clip's picture splits one small arc in two (an extra apex), which the heard
// impacts put right.
TEST(RunSound, ThirtyFpsApexHeightsBetterWithSound) {
  for (const std::string ball : {"tennis", "pingpong"}) {
    SCOPED_TRACE(ball);
    const auto dir = ScratchDir("fps30_" + ball);
    const SynthTruth t = Synth(dir, "--sound --hum --sound-offset 0.03 --fps 30 --noise 6 --exposure 0.02 --ball " + ball);
    double sq[2] = {0, 0};
    int n[2] = {0, 0};
    for (int with_sound = 0; with_sound < 2; ++with_sound) {
      const auto run = RunClip(dir / "clip.avi", "--ball " + ball + (with_sound ? "" : " --no-audio"),
                               dir / (with_sound ? "with" : "without"));
      for (const auto& r : ReadCsv(run / "peaks.csv")) {
        const int b = std::stoi(r.at("bounce"));
        if (b == 0 || b >= static_cast<int>(t.apex_heights_m.size()) || r.at("heard") == "heard only")
          continue;
        const double truth = t.apex_heights_m[b];
        const double h = CellNumber(r, "fused_height_m");
        if (with_sound) {
          EXPECT_NEAR(h, truth, std::max(0.002, 0.01 * truth)) << "bounce " << b;
          EXPECT_NEAR(CellNumber(r, "t_s"), t.apex_times_s[b], 0.05) << "bounce " << b;
        }
        sq[with_sound] += (h - truth) * (h - truth);
        ++n[with_sound];
      }
    }
    ASSERT_GE(n[1], 4);
    ASSERT_GE(n[0], 4);
    const double rms_without = std::sqrt(sq[0] / n[0]), rms_with = std::sqrt(sq[1] / n[1]);
    EXPECT_LT(rms_with, 0.5 * rms_without) << "rms " << rms_with * 1e3 << " mm with sound, "
                                           << rms_without * 1e3 << " mm without";
  }
}

// The live BOUNCE_PEAK carries the heard height: once an arc's closing impact is heard, its
// bounce goes out again with the flight-time height, while the stream runs (`--json`
// prints every peak event as published).
TEST(RunSound, LivePeaksCarryTheHeardHeightsAtThirtyFps) {
  const auto dir = ScratchDir("live_heard");
  const SynthTruth t = Synth(dir, "--sound --hum --sound-offset 0.03 --fps 30 --noise 6 --exposure 0.02 --ball tennis");
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " run " + (dir / "clip.avi").string() +
                           " --ball tennis --no-fit --speed 0 --json --lcm-url memq:// --out " +
                           (dir / "run").string(), &out), 0) << out;
  std::map<int, nlohmann::json> heard;  // bounce -> its heard peak message
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] != '{') continue;
    const auto j = nlohmann::json::parse(line);
    // A bounce's revision once its arc was heard end to end (revision 1), while the stream runs.
    if (j.value("event", "") != "revision" || j.value("revision", -1) != 1) continue;
    if (j["height_m"].get<double>() == j["flight_height_m"].get<double>() && j["height_px"].is_null())
      heard[j["live_bounce"].get<int>()] = j;
  }
  ASSERT_GE(heard.size(), 4u) << out;
  for (const auto& [b, j] : heard) {
    ASSERT_LT(b, static_cast<int>(t.apex_heights_m.size()));
    const double truth = t.apex_heights_m[b];
    EXPECT_NEAR(j["height_m"].get<double>(), truth, std::max(0.002, 0.01 * truth)) << "bounce " << b;
    // Sent once the arc's end was heard, while the stream ran: at once from the third
    // bounce on, the first two once three seen impacts have checked the sound.
    const double emitted = j["sent_t_s"].get<double>(), end = j["impact_after_t_s"].get<double>();
    EXPECT_GE(emitted, end - 0.001) << "bounce " << b;
    EXPECT_LT(emitted, 4.4) << "bounce " << b;
    if (b >= 3) { EXPECT_LT(emitted, end + 0.2) << "bounce " << b; }
  }
}

TEST(RunSound, RealClipsHeardTrainsAndNothingFromNoise) {
  const auto clips = testing::RealClipsDir();
  if (clips.empty()) GTEST_SKIP() << "shared real clips not found";
  const auto dir = ScratchDir("real");
  struct Case {
    std::string file, ball;
    int min_heard, max_heard;  // audio/both rows expected
  };
  // Counts from the clips' README (rebound apexes a person sees + 1 impact each) and
  // above where the ball bounces on below what the video resolves; the slow-motion clip's
  // sound holds no bounce train.
  for (const Case& c : {Case{"basketball_tile_ochre_24fps.mp4", "basketball", 5, 12},
                        Case{"football_door_wood_20fps.mp4", "football", 8, 12},
                        Case{"pingpong_white_blackcloth_24fps.mov", "pingpong", 9, 12},
                        Case{"tennis_door_wood_20fps.mp4", "tennis", 4, 6},
                        Case{"red_ball_ceiling_drop_slomo120_30fps.mp4", "pingpong", 0, 0}}) {
    SCOPED_TRACE(c.file);
    const auto run = RunClip(clips / c.file, "--max-frames 300 --ball " + c.ball, dir / c.file);
    int heard = 0;
    for (const auto& r : ReadCsv(run / "impacts.csv")) heard += r.at("source") != "video";
    EXPECT_GE(heard, c.min_heard);
    EXPECT_LE(heard, c.max_heard);
  }
}

// `capture --replay` hears the clip's own sound beside the picture: every impact faster
// than 0.5 m/s goes out on IMPACT (source audio), timed within 0.3 ms of the truth on the
// frames' clock (first BALL_BOX = the clip's t = 0); --no-audio sends none.
TEST(RunSound, CaptureReplayPublishesTheHeardImpacts) {
  const auto dir = ScratchDir("capture");
  const SynthTruth t = Synth(dir, "--sound --fps 60 --ball tennis");
  for (const bool no_audio : {false, true}) {
    const auto log_path = dir / (no_audio ? "silent.lcm" : "heard.lcm");
    std::string out;
    ASSERT_EQ(RunCommand(BouncefitExe() + " capture --replay " + (dir / "clip.avi").string() +
                             " --speed 0 -q --lcm-url memq:// --log " + log_path.string() +
                             (no_audio ? " --no-audio" : ""),
                         &out),
              0)
        << out;
    lcm::LogFile log(log_path.string(), "r");
    ASSERT_TRUE(log.good());
    int64_t t0 = -1;
    std::vector<double> heard_s;
    while (const lcm::LogEvent* ev = log.readNextEvent()) {
      if (ev->channel == "BALL_BOX" && t0 < 0) {
        ball_box_t b;
        ASSERT_GT(b.decode(ev->data, 0, ev->datalen), 0);
        t0 = b.utime;
      } else if (ev->channel == "IMPACT") {
        impact_t m;
        ASSERT_GT(m.decode(ev->data, 0, ev->datalen), 0);
        EXPECT_EQ(m.source, "audio");
        heard_s.push_back(static_cast<double>(m.utime));
      }
    }
    ASSERT_GE(t0, 0);
    if (no_audio) {
      EXPECT_TRUE(heard_s.empty());
      continue;
    }
    for (double& h : heard_s) h = (h - t0) * 1e-6;
    int checked = 0;
    for (size_t k = 0; k < t.impact_times_s.size(); ++k) {
      if (t.impact_speeds_mps[k] <= 0.5) continue;
      double best = 1e9;
      for (double h : heard_s) best = std::min(best, std::abs(h - t.impact_times_s[k]));
      EXPECT_LT(best, 0.0003) << "impact at " << t.impact_times_s[k] << " s";
      ++checked;
    }
    EXPECT_GE(checked, 5);
    for (double h : heard_s) {
      double best = 1e9;
      for (double ti : t.impact_times_s) best = std::min(best, std::abs(h - ti));
      EXPECT_LT(best, 0.0003) << "invented impact at " << h << " s";
    }
  }
}

// Phone clips whose sound holds every impact (AAC: each click behind its encoder's pre-echo
// ramp), where the picture misses impacts, sees one twice or comes in mid-drop: every bounce
// the sound bounds is a row, numbered in order from the first impact, its height falling; and
// every impact the picture sees while the sound hears the drop is one the sound heard (a
// seen-only impact there is one impact seen twice). After the last click heard, the picture
// may still see a bounce too small to hear.
TEST(RunSound, PhoneClipsEveryHeardBounceInOrder) {
  const auto clips = testing::RealClipsDir();
  if (clips.empty()) GTEST_SKIP() << "shared real clips not found";
  const auto dir = ScratchDir("phone_order");
  struct Case {
    std::string file, ball;
    size_t min_rows;  // the README's count (low end), or above where the sound hears more
  };
  // The white clip's eighth hop, heard, lasts 3.8 frames (0.030 m by its flight time): shorter
  // than the 4 frames the picture resolves, it is an impact, not a row.
  for (const Case& c : {Case{"pingpong_white_blackcloth_24fps.mov", "pingpong", 7},
                        Case{"basketball_tile_ochre_24fps.mp4", "basketball", 6},
                        Case{"tennis_door_wood_20fps.mp4", "tennis", 3},
                        Case{"football_door_wood_20fps.mp4", "football", 7}}) {
    SCOPED_TRACE(c.file);
    const auto run = RunClip(clips / c.file, "--ball " + c.ball, dir / c.file);
    const auto peaks = ReadCsv(run / "peaks.csv");
    ASSERT_GE(peaks.size(), c.min_rows);
    for (size_t k = 1; k < peaks.size(); ++k) {
      EXPECT_EQ(std::stoi(peaks[k].at("bounce")), std::stoi(peaks[k - 1].at("bounce")) + 1) << "row " << k;
      EXPECT_LT(CellNumber(peaks[k], "fused_height_m"), CellNumber(peaks[k - 1], "fused_height_m")) << "row " << k;
    }
    const auto impacts = ReadCsv(run / "impacts.csv");
    double last_heard_s = 0;
    for (const auto& r : impacts)
      if (r.at("source") != "video") last_heard_s = CellNumber(r, "t_s");
    for (const auto& r : impacts) {
      if (CellNumber(r, "t_s") < last_heard_s) { EXPECT_NE(r.at("source"), "video") << r.at("t_s"); }
    }
  }
}

// The football clip read at its stamps (--keep-frame-times; its pictures were taken at 30 fps,
// and read at their own times the picture sees the first impact too): the picture first sees
// the ball at the top of its first rebound and takes that for a release (bounce 0); the impact
// heard before it is kept, and the bounces are numbered from it: the picture's release is
// bounce 1, and every later bounce follows in order.
TEST(RunSound, ABounceHeardBeforeThePictureFoundTheBallNumbersTheRest) {
  const auto clips = testing::RealClipsDir();
  if (clips.empty()) GTEST_SKIP() << "shared real clips not found";
  const auto dir = ScratchDir("before_lock");
  const auto run = RunClip(clips / "football_door_wood_20fps.mp4", "--ball football --keep-frame-times", dir / "run");
  const auto impacts = ReadCsv(run / "impacts.csv");
  ASSERT_GE(impacts.size(), 8u);
  EXPECT_EQ(impacts[0].at("source"), "audio");
  int both = 0;
  for (const auto& r : impacts) both += r.at("source") == "both";
  EXPECT_GE(both, 6);
  const auto peaks = ReadCsv(run / "peaks.csv");
  ASSERT_GE(peaks.size(), 7u);
  // A heard-only row still carries a height in height_m (its flight-time height), so readers
  // of height_m (fit --peaks, report, the real-clips check) never see an empty cell.
  for (const auto& r : peaks)
    if (r.at("heard") == "heard only") {
      ASSERT_FALSE(r.at("height_m").empty());
      EXPECT_DOUBLE_EQ(CellNumber(r, "height_m"), CellNumber(r, "flight_height_m"));
    }
  for (size_t k = 0; k < peaks.size(); ++k) {
    EXPECT_EQ(std::stoi(peaks[k].at("bounce")), static_cast<int>(k) + 1);
    if (k > 0) {
      EXPECT_LT(CellNumber(peaks[k], "fused_height_m"), CellNumber(peaks[k - 1], "fused_height_m"));
    }
  }
}

// The football clip's bounce train goes on after the last impact the picture saw, lower and
// lower, the ball in view and followed in every frame: the arc that begins at that impact is a
// row, heard only, while the arcs after it, which the picture watched and showed no bounce in,
// stay impacts (impacts.csv): a person counts 4-8 rebounds, not 10.
TEST(RunSound, ArcsThePictureFollowedWithoutSeeingAreImpactsNotBounces) {
  const auto clips = testing::RealClipsDir();
  if (clips.empty()) GTEST_SKIP() << "shared real clips not found";
  const auto dir = ScratchDir("watched");
  const auto run = RunClip(clips / "football_door_wood_20fps.mp4", "--ball football", dir / "run");
  const auto peaks = ReadCsv(run / "peaks.csv");
  int rebounds = 0, heard_only = 0;
  double last_row_t = 0;
  for (const auto& r : peaks) {
    rebounds += std::stoi(r.at("bounce")) >= 1;
    heard_only += r.at("heard") == "heard only";
    last_row_t = std::max(last_row_t, CellNumber(r, "t_s"));
  }
  EXPECT_GE(rebounds, 4);
  EXPECT_LE(rebounds, 8);
  EXPECT_GE(heard_only, 1) << "the arc that begins at the last seen impact";
  int heard_later = 0;
  for (const auto& i : ReadCsv(run / "impacts.csv"))
    heard_later += i.at("source") == "audio" && CellNumber(i, "t_s") > last_row_t;
  EXPECT_GE(heard_later, 3) << "the impacts heard after the last row are still listed";
}

// The clip begins on the ball rising from an impact before it (neither heard nor seen): with
// the sound used, rows are numbered by the impacts since the release, and the one the picture
// came in after counts too: bounce 1 is the first apex, not a "release".
TEST(RunSound, AClipThatBeginsMidBounceNumbersItsFirstApexOne) {
  const auto dir = ScratchDir("midbounce");
  const SynthTruth t = Synth(dir, "--sound --fps 60 --ball tennis --start-after-release 0.6");
  const auto rows = ReadCsv(RunClip(dir / "clip.avi", "--ball tennis", dir / "run") / "peaks.csv");
  const auto summary = nlohmann::json::parse(std::ifstream(dir / "run" / "summary.json"));
  ASSERT_TRUE(summary["sound"]["used"].get<bool>()) << summary["sound"]["verdict"];
  ASSERT_GE(rows.size(), 4u);
  for (size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k].at("bounce"), std::to_string(k + 1)) << "row " << k;
    // The truth lists the apexes in the clip: the first rebound first.
    if (k < t.apex_heights_m.size() && t.apex_heights_m[k] >= 0.05) {
      EXPECT_NEAR(CellNumber(rows[k], "height_m"), t.apex_heights_m[k], std::max(0.002, 0.01 * t.apex_heights_m[k]))
          << "row " << k;
    }
  }
}

// The ball held still in view, then dropped, with a click heard during the hold where a
// bounce into the release would have landed (the train's flights, traced back, put an impact
// there): the release was seen from a hold, so it stays bounce 0, on no heard arc; the click
// is listed as heard, with no flight to the first impact; every rebound keeps its number.
TEST(RunSound, AClickHeardWhileTheBallIsHeldLeavesTheReleaseBounceZero) {
  const auto dir = ScratchDir("held_click");
  const std::string flags = "--sound --fps 60 --ball tennis --hold 1";
  const SynthTruth plain = Synth(dir, flags);
  ASSERT_GE(plain.impact_times_s.size(), 3u);
  const double t1 = plain.impact_times_s[0], t2 = plain.impact_times_s[1], t3 = plain.impact_times_s[2];
  const double click_s = t1 - (t2 - t1) * (t2 - t1) / (t3 - t2);
  ASSERT_GT(click_s, 0.1);
  ASSERT_LT(click_s, plain.release_t_s - 0.1) << "the click falls in the hold";
  const SynthTruth t = Synth(dir, flags + " --extra-click " + std::to_string(click_s));
  ASSERT_EQ(t.extra_clicks_s.size(), 1u);
  const auto run = RunClip(dir / "clip.avi", "--ball tennis", dir / "run");
  const auto summary = nlohmann::json::parse(std::ifstream(run / "summary.json"));
  ASSERT_TRUE(summary["sound"]["used"].get<bool>()) << summary["sound"]["verdict"];
  ASSERT_TRUE(summary["drops"][0]["released_from_hold"].get<bool>());
  bool click_heard = false;
  for (const auto& r : ReadCsv(run / "impacts.csv"))
    if (std::abs(CellNumber(r, "t_s") - click_s) < 0.002) {
      click_heard = true;
      EXPECT_TRUE(r.at("flight_s").empty()) << "a flight across the hold";
    }
  EXPECT_TRUE(click_heard) << "the fusion did not take the click for an impact: nothing tested";
  const auto rows = ReadCsv(run / "peaks.csv");
  ASSERT_GE(rows.size(), 5u);
  EXPECT_NEAR(CellNumber(rows[0], "t_s"), t.release_t_s, 0.02);
  EXPECT_TRUE(rows[0].at("heard").empty());
  for (size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k].at("bounce"), std::to_string(k)) << "row " << k;
    if (k < t.apex_heights_m.size() && t.apex_heights_m[k] >= 0.05) {
      EXPECT_NEAR(CellNumber(rows[k], "fused_height_m"), t.apex_heights_m[k], std::max(0.002, 0.01 * t.apex_heights_m[k]))
          << "row " << k;
    }
  }
}

// superball_cyan_suitcase_tile_30fps: the ball held still, then dropped; a sound 0.3 s before
// the release fits a bounce train traced back. A person counts 3 rebounds; the author's
// hand-tracked heights (its .author_bounce.csv): release 47.9 cm, rebounds 36.5, 28.1, 22.0 cm,
// each over the one before (scale-free) within 0.04.
TEST(RunSound, RealClipHeldThenDroppedIsAReleaseAndThreeRebounds) {
  const auto clips = testing::RealClipsDir();
  if (clips.empty()) GTEST_SKIP() << "shared real clips not found";
  const auto run = RunClip(clips / "superball_cyan_suitcase_tile_30fps.mp4", "--ball tennis",
                           ScratchDir("superball") / "run");
  const auto rows = ReadCsv(run / "peaks.csv");
  ASSERT_EQ(rows.size(), 4u);
  const double author_m[] = {0.479, 0.365, 0.281, 0.220};
  EXPECT_TRUE(rows[0].at("heard").empty()) << "the release on a heard arc";
  EXPECT_NEAR(CellNumber(rows[0], "t_s"), 0.617, 1 / 30.0) << "the author's track: still at 0.600 s, falling at 0.633 s";
  for (size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k].at("bounce"), std::to_string(k)) << "row " << k;
    if (k > 0) {
      EXPECT_NEAR(CellNumber(rows[k], "fused_height_m") / CellNumber(rows[k - 1], "fused_height_m"), author_m[k] / author_m[k - 1],
                  0.04)
          << "row " << k;
    }
  }
}

// At 30 fps a hop shorter than 4 frames (2.2 cm) is below what the picture shows: the detector
// ends the drop there, and the bounces heard after it, as short, are impacts (impacts.csv), not
// rows of peaks.csv; every bounce the picture resolves is a row.
TEST(RunSound, HopsHeardShorterThanThePictureResolvesAreImpactsNotBounces) {
  const auto dir = ScratchDir("short_hops");
  const SynthTruth t = Synth(dir, "--sound --fps 30 --ball tennis");
  const auto out = RunClip(dir / "clip.avi", "--ball tennis", dir / "run");
  const auto rows = ReadCsv(out / "peaks.csv");
  const auto impacts = ReadCsv(out / "impacts.csv");
  const double min_m = 9.81 * std::pow(4 / 30.0, 2) / 8;
  double last_row_t = 0;
  for (const auto& r : rows) {
    last_row_t = std::max(last_row_t, CellNumber(r, "t_s"));
    if (r.at("heard") == "heard only") { EXPECT_GE(CellNumber(r, "height_m"), min_m) << "row " << r.at("bounce"); }
  }
  int resolvable = 0;
  for (size_t k = 1; k < t.apex_heights_m.size(); ++k) resolvable += t.apex_heights_m[k] >= min_m;
  int rebounds = 0;
  for (const auto& r : rows) rebounds += std::stoi(r.at("bounce")) >= 1;
  EXPECT_EQ(rebounds, resolvable);
  int heard_later = 0;
  for (const auto& i : impacts) heard_later += i.at("source") == "audio" && CellNumber(i, "t_s") > last_row_t;
  EXPECT_GE(heard_later, 2) << "the short hops' impacts are still listed";
}

}  // namespace
}  // namespace bouncefit
