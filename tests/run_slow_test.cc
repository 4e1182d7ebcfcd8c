// `bouncefit run` end to end, as a user runs it: a rendered clip with known truth in, the
// output directory of docs/FORMATS.md out, and a live terminal while it replays.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <cctype>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "bouncefit/bounce_peak_t.hpp"
#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::ReadCsv;
using testing::RunCommand;
namespace fs = std::filesystem;

// A 1 m ping-pong drop, 640x480 at 120 fps, rendered once per test process.
const fs::path& PingPongClip() {
  static const fs::path clip = [] {
    const fs::path dir = testing::ScratchDir("run_clip");
    const fs::path c = dir / "pingpong.avi";
    std::string out;
    const int rc = RunCommand(BouncefitExe() + " synth --quiet --ball pingpong --drop-height 1.0"
                                               " --duration 3.5 --noise 3 --roll 1 --seed 5 --out " +
                                  c.string(),
                              &out);
    EXPECT_EQ(rc, 0) << out;
    return c;
  }();
  return clip;
}


TEST(Run, WritesTheOutputDirectoryWithPeaksThatMatchTruth) {
  const fs::path dir = testing::ScratchDir("run_outputs") / "out";
  std::string out;
  const int rc = RunCommand(BouncefitExe() + " run " + PingPongClip().string() + " --out " +
                                dir.string() +
                                " --speed 0 --lcm-url memq:// --model point-mass --quiet",
                            &out);
  ASSERT_EQ(rc, 0) << out;
  EXPECT_TRUE(out.empty()) << "--quiet printed: " << out;

  const SynthTruth truth = LoadSynthTruth(SynthTruthPathFor(PingPongClip()));
  const auto track = ReadCsv(dir / "track.csv");
  EXPECT_EQ(static_cast<int>(track.size()), truth.frame_count);
  ASSERT_FALSE(track.empty());
  EXPECT_TRUE(track[0].count("cx_px") && track[0].count("h_px"));

  // Every apex above 1 cm, in metres from the detector's own calibration.
  const auto peaks = ReadCsv(dir / "peaks.csv");
  int checked = 0;
  for (size_t i = 0; i < truth.apex_heights_m.size(); ++i) {
    const double h = truth.apex_heights_m[i];
    if (h < 0.01 || truth.apex_times_s[i] + truth.release_t_s > truth.frame_count / truth.fps - 0.1)
      continue;
    ASSERT_LT(i, peaks.size()) << "apex " << i << " missing";
    EXPECT_EQ(std::stoi(peaks[i].at("bounce")), static_cast<int>(i));
    EXPECT_NEAR(std::stod(peaks[i].at("height_m")), h, std::max(0.002, 0.01 * h)) << "apex " << i;
    ++checked;
  }
  EXPECT_GE(checked, 4);

  nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir / "summary.json"));
  EXPECT_EQ(summary["frames"].get<int>(), truth.frame_count);
  EXPECT_EQ(summary["dropped_frames"].get<int>(), 0);
  EXPECT_TRUE(fs::exists(dir / "coefficients.json"));
  // simulated.csv: the fitted ball released at the recorded release, on the run's clock.
  const auto simulated = ReadCsv(dir / "simulated.csv");
  ASSERT_FALSE(simulated.empty());
  EXPECT_NEAR(std::stod(simulated.front().at("t_s")), std::stod(peaks.front().at("t_s")), 1e-3);
  EXPECT_NEAR(summary["calibration"]["px_per_m"].get<double>(), truth.px_per_m,
              0.01 * truth.px_per_m);

  // fit.jsonl: one JSON object per line, the last one final.
  std::ifstream fits(dir / "fit.jsonl");
  std::string line, last;
  int lines = 0;
  while (std::getline(fits, line)) {
    EXPECT_NO_THROW(nlohmann::json::parse(line)) << line;
    last = line;
    ++lines;
  }
  EXPECT_GE(lines, 2);
  EXPECT_TRUE(nlohmann::json::parse(last)["final"].get<bool>());

  // session.lcm: the capture node's log, a box per frame (what detect and fit need again).
  lcm::LogFile log((dir / "session.lcm").string(), "r");
  ASSERT_TRUE(log.good());
  std::map<std::string, int> per_channel;
  while (const lcm::LogEvent* ev = log.readNextEvent()) ++per_channel[ev->channel];
  EXPECT_EQ(per_channel["BALL_BOX"], truth.frame_count);
  EXPECT_EQ(per_channel["STREAM"], 2);

  // The bus, as the console follows it (--json): each apex once, then again when its drop
  // ended with its height refitted with the whole drop (revision 2), as peaks.csv's
  // refit_height_m says; then its row of peaks.csv (revision 3).
  const fs::path again = dir.parent_path() / "json";
  ASSERT_EQ(RunCommand(BouncefitExe() + " run " + PingPongClip().string() + " --out " + again.string() +
                           " --speed 0 --lcm-url memq:// --model point-mass --json",
                       &out),
            0)
      << out;
  std::map<int, std::map<int, bouncefit::bounce_peak_t>> sent;  // live bounce -> revision -> message
  std::map<std::string, int> events;
  std::istringstream lines_in(out);
  for (std::string l; std::getline(lines_in, l);) {
    const auto j = nlohmann::json::parse(l);
    ++events[j["event"].get<std::string>()];
    if (j["event"] != "peak" && j["event"] != "revision") continue;
    bouncefit::bounce_peak_t m{};
    m.bounce = j["bounce"];
    m.revision = j["revision"];
    m.height_m = j["height_m"].is_null() ? NAN : j["height_m"].get<double>();
    sent[j["live_bounce"].get<int>()][m.revision] = m;
  }
  EXPECT_EQ(events["peak"], static_cast<int>(peaks.size()));  // a peak line per row
  int refitted = 0;
  for (const auto& row : peaks) {
    const auto& revisions = sent[std::stoi(row.at("bounce"))];
    ASSERT_TRUE(revisions.count(0)) << "bounce " << row.at("bounce");
    EXPECT_NEAR(revisions.at(0).height_m, std::stod(row.at("height_m")), 1e-5);
    ASSERT_TRUE(revisions.count(3));
    if (row.at("refit_height_m").empty()) continue;
    ASSERT_TRUE(revisions.count(2)) << "bounce " << row.at("bounce");
    EXPECT_NEAR(revisions.at(2).height_m, std::stod(row.at("refit_height_m")), 1e-5);
    ++refitted;
  }
  EXPECT_GE(refitted, 4);
  EXPECT_GE(events["calibration"], 1);
  int again_lines = 0;
  std::ifstream again_fits(again / "fit.jsonl");
  for (std::string l; std::getline(again_fits, l);) ++again_lines;
  EXPECT_EQ(events["fit"], again_lines);
  EXPECT_EQ(events["summary"], 1);
}

// A clip from one of FFmpeg's test sources (lavfi), e.g. "color=c=gray:s=320x240:r=30".
void MakeLavfiClip(const std::string& source, double seconds, const std::string& codec,
                   const fs::path& path) {
  std::string out;
  ASSERT_EQ(RunCommand("ffmpeg -v error -y -f lavfi -i " + source + " -t " + std::to_string(seconds) +
                           " " + codec + " '" + path.string() + "'",
                       &out),
            0)
      << out;
}

// `bouncefit run CLIP` into `out_dir`, with no fit and no pacing; its exit status.
int RunOn(const fs::path& clip, const fs::path& out_dir, std::string* out) {
  return RunCommand(BouncefitExe() + " run " + clip.string() + " --no-fit --speed 0 --out " +
                        out_dir.string() + " --lcm-url memq://",
                    out);
}

TEST(Run, BadInputIsOneLineErrorAndNonZero) {
  std::string out;
  EXPECT_NE(RunCommand(BouncefitExe() + " run /no/such/clip.avi --out /tmp/x", &out), 0);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;

  const fs::path dir = testing::ScratchDir("run_bad");
  const fs::path corrupt = dir / "corrupt.avi";
  std::ofstream(corrupt) << "RIFF this is not a video at all";
  EXPECT_NE(RunCommand(BouncefitExe() + " run " + corrupt.string() + " --out " +
                           (dir / "out").string() + " --lcm-url memq://",
                       &out),
            0);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_NE(out.find("error"), std::string::npos) << out;

  EXPECT_NE(RunCommand(BouncefitExe() + " run " + PingPongClip().string() +
                           " --ball bowling --out " + (dir / "out2").string(),
                       &out),
            0);
  EXPECT_NE(out.find("unknown ball"), std::string::npos) << out;

  // A pick outside the frame is refused before any output exists.
  const fs::path picked = dir / "out_pick";
  EXPECT_NE(RunCommand(BouncefitExe() + " run " + PingPongClip().string() +
                           " --pick 5000,20 --out " + picked.string() + " --lcm-url memq://",
                       &out),
            0);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_NE(out.find("outside"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(picked));

  // A file cut short: how many frames of how many, and non-zero when nothing usable came.
  const fs::path clip = PingPongClip();
  const fs::path cut = dir / "cut.avi";
  {
    std::ifstream in(clip, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 40);
  }
  EXPECT_NE(RunOn(cut, dir / "out_cut", &out), 0) << out;
  EXPECT_NE(out.find("ended after"), std::string::npos) << out;
  EXPECT_NE(out.find("frames it announces"), std::string::npos) << out;

  // A whole clip with no ball in it: said in one line, exit 3 (no bounce found).
  const fs::path empty = dir / "no_ball.mp4";
  MakeLavfiClip("color=c=gray:s=320x240:r=30", 1, "-pix_fmt yuv420p", empty);
  EXPECT_EQ(RunOn(empty, dir / "out_empty", &out), 3) << out;
  EXPECT_NE(out.find("no ball found in any of its 30 frames"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir / "out_empty" / "track.csv"));  // what was recorded is kept

  // Something that moves but never bounces (a test card's moving patch): what was taken for
  // the ball and that no bounce was found, said (it ended "done ... 0 peaks" without a word).
  const fs::path card = dir / "test_card.mp4";
  MakeLavfiClip("testsrc=s=320x240:r=30", 3, "-pix_fmt yuv420p", card);
  EXPECT_EQ(RunOn(card, dir / "out_card", &out), 3) << out;
  EXPECT_NE(out.find("no bounce found"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir / "out_card" / "track.csv"));

  // A damaged first picture in a clip with a sound track: FFmpeg's own complaints ("[h264 @
  // 0x...] error while decoding MB ...") stay quiet with the sound read beside the pictures,
  // as without it (they were printed); the run goes on to its end.
  const fs::path sounded = dir / "card_with_sound.mp4", damaged = dir / "card_damaged.mp4";
  ASSERT_EQ(RunCommand("ffmpeg -v error -y -f lavfi -i testsrc=s=320x240:r=30 -f lavfi -i sine=f=440 -t 3 "
                       "-c:v libx264 -pix_fmt yuv420p -c:a aac '" + sounded.string() + "'", &out),
            0)
      << out;
  ASSERT_EQ(RunCommand("ffprobe -v error -select_streams v:0 -read_intervals %+#1 -show_entries packet=pos,size "
                       "-of default=nw=1 '" + sounded.string() + "'", &out),
            0)
      << out;
  std::smatch pos, size;
  ASSERT_TRUE(std::regex_search(out, pos, std::regex("pos=(\\d+)")) && std::regex_search(out, size, std::regex("size=(\\d+)")))
      << out;
  {
    std::ifstream in(sounded, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const size_t from = std::stoul(pos[1]) + std::stoul(size[1]) / 4;
    ASSERT_LT(from + 64, bytes.size());
    uint32_t x = 1;  // 64 bytes of noise a quarter into the first picture's data
    for (size_t i = from; i < from + 64; ++i) x = x * 1103515245u + 12345u, bytes[i] = static_cast<char>((x >> 16) & 0xff);
    std::ofstream(damaged, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  EXPECT_EQ(RunOn(damaged, dir / "out_damaged", &out), 3) << out;
  EXPECT_EQ(out.find(" @ 0x"), std::string::npos) << out;
  EXPECT_NE(out.find("no bounce found"), std::string::npos) << out;

  // A picture too small to hold a ball: said so, not "ROI lies outside the 4x4 frame".
  const fs::path tiny = dir / "tiny.avi";
  MakeLavfiClip("testsrc=s=4x4:r=30", 1, "-c:v mjpeg", tiny);
  EXPECT_NE(RunOn(tiny, dir / "out_tiny", &out), 0) << out;
  EXPECT_NE(out.find("4x4 px picture is too small"), std::string::npos) << out;
}

std::string Tmux(const std::string& args) {
  std::string out;
  RunCommand("tmux " + args, &out);
  return out;
}

// A person watching the terminal: peaks and fit updates appear while the clip is still
// replaying, not all at the end.
TEST(Run, ShowsPeaksAndFitsLiveInATerminal) {
  std::string probe;
  if (RunCommand("tmux -V", &probe) != 0) GTEST_SKIP() << "tmux is not installed";
  const fs::path dir = testing::ScratchDir("run_live");
  const std::string session = "bouncefit_run_" + std::to_string(::getpid());
  const std::string cmd = BouncefitExe() + " run " + PingPongClip().string() + " --out " +
                          (dir / "out").string() +
                          " --lcm-url memq:// --model point-mass; echo RUN-EXITED; sleep 30";
  Tmux("new-session -d -x 160 -y 50 -s " + session + " \"" + cmd + "\"");

  // Sample the screen until the run exits, keeping the first screen that shows a peak and
  // the first that shows a fit update.
  std::string first_peak_screen, first_fit_screen, screen;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    screen = Tmux("capture-pane -p -t " + session);
    if (first_peak_screen.empty() && screen.find("peak  #1") != std::string::npos)
      first_peak_screen = screen;
    if (first_fit_screen.empty() && screen.find("fit   after") != std::string::npos)
      first_fit_screen = screen;
    if (screen.find("RUN-EXITED") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  Tmux("kill-session -t " + session);
  ASSERT_NE(screen.find("RUN-EXITED"), std::string::npos) << screen;
  ASSERT_FALSE(first_peak_screen.empty()) << screen;
  ASSERT_FALSE(first_fit_screen.empty()) << screen;
  // While those were on screen the replay was still going: no summary yet, and the progress
  // line showed less than the whole clip.
  for (const std::string* s : {&first_peak_screen, &first_fit_screen}) {
    EXPECT_EQ(s->find("run: done"), std::string::npos) << *s;
    EXPECT_NE(s->find("replay"), std::string::npos) << *s;
  }
  EXPECT_NE(screen.find("run: done"), std::string::npos) << screen;
}

// `watch` in its own terminal attaches to a `run` in another process and shows its peaks
// and its coefficients as they come.
TEST(Run, WatchInAnotherProcessShowsTheRunsPeaksAndCoefficients) {
  std::string probe;
  if (RunCommand("tmux -V", &probe) != 0) GTEST_SKIP() << "tmux is not installed";
  const fs::path dir = testing::ScratchDir("run_watch");
  const std::string url = testing::UniqueUdpmUrl();
  const std::string session = "bouncefit_watch_" + std::to_string(::getpid());
  Tmux("new-session -d -x 140 -y 45 -s " + session + " \"" + BouncefitExe() +
       " watch --lcm-url '" + url + "'\"");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  std::string out;
  const int rc = RunCommand(BouncefitExe() + " run " + PingPongClip().string() + " --out " +
                                (dir / "out").string() + " --lcm-url '" + url +
                                "' --model point-mass --quiet",
                            &out);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  const std::string screen = Tmux("capture-pane -p -t " + session);
  Tmux("send-keys -t " + session + " q");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const std::string sessions = Tmux("ls");
  Tmux("kill-session -t " + session);
  ASSERT_EQ(rc, 0) << out;

  // Every row the run wrote is on the dashboard, to the displayed 4 decimals: the height to
  // quote, which the detect node sent once the stream ended.
  const auto peaks = ReadCsv(dir / "out" / "peaks.csv");
  ASSERT_GE(peaks.size(), 4u);
  for (const auto& p : peaks) {
    const std::string text = fmt::format("{:.4f}", std::stod(p.at("fused_height_m")));
    EXPECT_NE(screen.find(text), std::string::npos) << "peak " << text << " not shown:\n" << screen;
  }
  // Each fitted bounce's row shows the final fit's simulated apex for that bounce, as
  // coefficients.json pairs them (by peaks.csv's bounce number, from the start apex).
  const auto coeffs = nlohmann::json::parse(std::ifstream(dir / "out" / "coefficients.json"));
  const auto& drop = coeffs["drops"][0];
  ASSERT_GE(drop["bounces"].size(), 2u) << drop.dump();
  std::istringstream lines(screen);
  std::map<int, std::string> rows;  // bounce number -> its row of the peaks table
  for (std::string line; std::getline(lines, line);)
    if (line.size() > 3 && std::isdigit(static_cast<unsigned char>(line[1])) && line[2] == ' ' &&
        (line[0] == ' ' || std::isdigit(static_cast<unsigned char>(line[0]))))
      rows.emplace(std::stoi(line.substr(0, 2)), line);
  for (size_t i = 0; i < drop["bounces"].size(); ++i) {
    const int bounce = drop["bounces"][i].get<int>();
    const std::string sim = fmt::format("{:.4f}", drop["simulated_m"][i].get<double>());
    ASSERT_TRUE(rows.count(bounce)) << "bounce " << bounce << " has no row:\n" << screen;
    EXPECT_NE(rows[bounce].find(sim), std::string::npos) << "bounce " << bounce << " sim " << sim << ":\n" << screen;
  }
  EXPECT_NE(rows[drop["start_bounce"].get<int>()].find("start"), std::string::npos) << screen;
  // The final fit's coefficients, by name.
  for (const char* name : {"restitution", "drag_coefficient", "(final)"})
    EXPECT_NE(screen.find(name), std::string::npos) << name << "\n" << screen;
  EXPECT_NE(screen.find("px/m"), std::string::npos) << screen;
  // q ended the dashboard.
  EXPECT_EQ(sessions.find(session), std::string::npos) << sessions;
}

}  // namespace
}  // namespace bouncefit
