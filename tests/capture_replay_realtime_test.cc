// Capture and replay, end to end with real processes:
//  - `bouncefit capture --replay CLIP` and `bouncefit detect` in two processes talk over udpm
//    (ttl=0); the detector sees every box; lcm-logger records them; replaying that log with
//    `bouncefit replay-log` gives the same boxes and the same peaks.
//  - Real-time pacing: a 5 s clip replays in 5 s +- 2% (and --speed 1.5 in 3.33 s); --speed 0
//    runs at decode speed. (Speed 2 needs 240 decoded 640x480 frames/s: on a loaded 2-core
//    machine decoding alone reaches ~280, too close to test pacing rather than the CPU.)
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <regex>
#include <sstream>

#include <unistd.h>

#include "bouncefit/ball_box_t.hpp"
#include "pipeline/lcm_log_replay.h"
#include "replay/video_file_source.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::RunCommand;

class CaptureReplaySlow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ctest runs each test in its own process: render the clip once, reuse it after.
    dir_ = std::filesystem::current_path() / "scratch" / "capture_replay_slow";
    std::filesystem::create_directories(dir_);
    clip_ = (dir_ / "drop5s.avi").string();
    if (std::filesystem::exists(clip_)) return;
    const std::string tmp = (dir_ / ("drop5s." + std::to_string(::getpid()) + ".avi")).string();
    std::string out;
    // 600 frames at 120 fps: exactly 5 s of footage.
    ASSERT_EQ(RunCommand(BouncefitExe() + " synth --duration 5 --fps 120 -q -o '" + tmp + "'", &out), 0)
        << out;
    std::filesystem::rename(tmp, clip_);
  }
  static std::filesystem::path dir_;
  static std::string clip_;
};
std::filesystem::path CaptureReplaySlow::dir_;
std::string CaptureReplaySlow::clip_;

std::vector<std::vector<uint8_t>> Boxes(const std::string& log) {
  std::vector<std::vector<uint8_t>> out;
  LcmLogReader reader(log);
  while (auto e = reader.Next())
    if (e->channel == "BALL_BOX") out.push_back(e->data);
  return out;
}

std::vector<std::string> PeakLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("peak", 0) == 0 || line.rfind("  bounce", 0) == 0) lines.push_back(line);
  return lines;
}

struct Timing {
  double wall = 0, stream = 0, read = 0, track = 0;
  long frames = 0;
};

Timing ParseFinal(const std::string& out) {
  static const std::regex re(
      R"(capture: done: (\d+) frames.*wall ([0-9.]+) s, stream ([0-9.]+) s \(read ([0-9.]+) s, track ([0-9.]+) s\))");
  std::smatch m;
  Timing t;
  if (std::regex_search(out, m, re)) {
    t.frames = std::stol(m[1]);
    t.wall = std::stod(m[2]);
    t.stream = std::stod(m[3]);
    t.read = std::stod(m[4]);
    t.track = std::stod(m[5]);
  }
  return t;
}

TEST_F(CaptureReplaySlow, TwoProcessesOverUdpmLoggerAndReplayGiveTheSameBoxesAndPeaks) {
  const std::string url = testing::UniqueUdpmUrl();
  const auto d = dir_ / "two_process";
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  const std::string exe = BouncefitExe();
  std::ostringstream sh;
  sh << "set -u\ncd '" << d.string() << "'\n"
     << "wait_for() { for i in $(seq 100); do grep -q \"$2\" \"$1\" 2>/dev/null && return 0; sleep 0.1; done; return 1; }\n"
     << "lcm-logger --lcm-url='" << url << "' -f session.lcm > logger.txt 2>&1 & L=$!\n"
     << exe << " detect --lcm-url '" << url << "' --exit-after-idle 4 > detect1.txt 2>&1 & D=$!\n"
     << "wait_for detect1.txt listening || echo 'detect did not start'\n"
     << "sleep 1\n"
     << exe << " capture --replay '" << clip_ << "' --lcm-url '" << url
     << "' --log capture.lcm --quiet > capture.txt 2>&1; echo \"capture rc $?\"\n"
     << "wait $D; echo \"detect rc $?\"\n"
     << "kill -INT $L; wait $L\n"
     << exe << " detect --lcm-url '" << url << "' --exit-after-idle 4 > detect2.txt 2>&1 & D=$!\n"
     << "wait_for detect2.txt listening || echo 'detect did not start'\n"
     << exe << " replay-log session.lcm --lcm-url '" << url
     << "' --channels BALL_BOX --speed 2 > replay.txt 2>&1; echo \"replay rc $?\"\n"
     << "wait $D; echo \"detect2 rc $?\"\n"
     // lcm-logplayer plays capture's own --log; a fresh lcm-logger records what it played.
     << "lcm-logger --lcm-url='" << url << "' -f played.lcm > logger2.txt 2>&1 & L=$!\n"
     << "sleep 1\n"
     << "lcm-logplayer -s 4 --lcm-url='" << url << "' capture.lcm; echo \"logplayer rc $?\"\n"
     << "sleep 0.5; kill -INT $L; wait $L\n";
  std::ofstream(d / "run.sh") << sh.str();
  std::string out;
  RunCommand("bash '" + (d / "run.sh").string() + "'", &out);
  EXPECT_NE(out.find("capture rc 0"), std::string::npos) << out;
  EXPECT_NE(out.find("detect rc 0"), std::string::npos) << out;
  EXPECT_NE(out.find("replay rc 0"), std::string::npos) << out;
  EXPECT_NE(out.find("detect2 rc 0"), std::string::npos) << out;
  const std::string capture = testing::ReadFile(d / "capture.txt");
  const std::string detect1 = testing::ReadFile(d / "detect1.txt");
  const std::string detect2 = testing::ReadFile(d / "detect2.txt");
  EXPECT_NE(capture.find("capture: done: 600 frames, 0 dropped"), std::string::npos) << capture;
  EXPECT_NE(capture.find("600 published"), std::string::npos) << capture;

  // The detector, another process, saw every box.
  EXPECT_NE(detect1.find("detect: done: 600 boxes"), std::string::npos) << detect1;
  // lcm-logger, a third, recorded every box, byte for byte what capture published.
  const auto published = Boxes((d / "capture.lcm").string());
  const auto logged = Boxes((d / "session.lcm").string());
  ASSERT_EQ(published.size(), 600u);
  ASSERT_EQ(logged.size(), 600u);
  for (std::size_t i = 0; i < 600; ++i) EXPECT_EQ(logged[i], published[i]) << "box " << i;
  // Replaying the log: the same boxes reach the detector, and it finds the same peaks.
  EXPECT_NE(detect2.find("detect: done: 600 boxes"), std::string::npos) << detect2;
  const auto peaks1 = PeakLines(detect1), peaks2 = PeakLines(detect2);
  EXPECT_GE(peaks1.size(), 3u) << detect1;
  EXPECT_EQ(peaks1, peaks2) << detect1 << "\n----\n" << detect2;
  // lcm-logplayer reads our log: everything it played arrived, byte for byte.
  EXPECT_NE(out.find("logplayer rc 0"), std::string::npos) << out;
  const auto played = Boxes((d / "played.lcm").string());
  EXPECT_EQ(played, published);
  std::printf("two processes: %zu boxes, %zu peak lines, identical after replay-log\n",
              logged.size(), peaks1.size());
}

TEST_F(CaptureReplaySlow, FiveSecondClipReplaysInFiveSecondsAndScalesWithSpeed) {
  for (double speed : {1.0, 1.5}) {
    std::string out;
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(RunCommand(BouncefitExe() + " capture --replay '" + clip_ +
                             "' --lcm-url memq:// --quiet --speed " + std::to_string(speed),
                         &out),
              0)
        << out;
    const double process_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const Timing t = ParseFinal(out);
    ASSERT_EQ(t.frames, 600) << out;
    const double want = 5.0 / speed;  // 600 frames of 1/120 s
    EXPECT_NEAR(t.wall, want, 0.02 * want) << out;
    EXPECT_LT(process_s, want * 1.02 + 1.0);  // plus start-up (LCM, FFmpeg open)
    std::printf("speed %.1f: clip %.3f s, replayed in %.3f s (%+.2f%%), stream span %.3f s, "
                "whole process %.3f s\n",
                speed, want, t.wall, 100 * (t.wall - want) / want, t.stream, process_s);
  }
}

TEST_F(CaptureReplaySlow, SpeedZeroRunsAtDecodeSpeed) {
  // Decode alone, in this process, as the baseline.
  const auto t0 = std::chrono::steady_clock::now();
  VideoFileSource source({clip_, false});
  int n = 0;
  while (source.Next()) ++n;
  const double decode_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(n, 600);
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " capture --replay '" + clip_ +
                           "' --lcm-url memq:// --quiet --speed 0",
                       &out),
            0)
      << out;
  const Timing t = ParseFinal(out);
  ASSERT_EQ(t.frames, 600) << out;
  EXPECT_LT(t.wall, 5.0 * 0.8);                  // not paced to the clip's 5 s
  EXPECT_LT(t.wall, t.read + t.track + 0.25);    // nothing but decoding, tracking, publishing
  EXPECT_LT(t.read, decode_s * 1.5 + 0.1);       // decoding as fast as decoding alone
  std::printf("speed 0: %.3f s for 600 frames (%.0f fps): decode %.3f s, track %.3f s; "
              "decode alone %.3f s (%.0f fps)\n",
              t.wall, 600 / t.wall, t.read, t.track, decode_s, 600 / decode_s);
}

}  // namespace
}  // namespace bouncefit
