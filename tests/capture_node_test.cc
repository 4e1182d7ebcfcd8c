// The capture node and command: FrameSource -> Tracker -> one BALL_BOX per frame, from a
// clip or from the (fake) camera alike; --record keeps the camera's timing; failures keep
// what was captured; bad input is one line and a non-zero exit.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <fstream>
#include <regex>

#include <unistd.h>

#include "bouncefit/ball_box_t.hpp"
#include "capture/frame_recorder.h"
#include "capture/v4l2_camera.h"
#include "tests/v4l2_fake_device.h"
#include "msgs/lcm_bus.h"
#include "msgs/lcm_log_recorder.h"
#include "pipeline/lcm_log_replay.h"
#include "replay/video_file_source.h"
#include "tests/test_support.h"
#include "track/node/capture_node.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::RunCommand;

// A 1.5 s synth drop at 120 fps, 320x240. ctest runs every test in a process of its own:
// render it once and reuse it (written under a temporary name, then renamed).
std::string SynthClip() {
  static std::string path;
  if (!path.empty()) return path;
  const auto dir = std::filesystem::current_path() / "scratch" / "capture_node_clip";
  const std::string p = (dir / "drop.avi").string();
  if (!std::filesystem::exists(p)) {
    std::filesystem::create_directories(dir);
    const std::string tmp = (dir / ("drop." + std::to_string(::getpid()) + ".avi")).string();
    std::string out;
    const int rc = RunCommand(BouncefitExe() + " synth --duration 1.5 --fps 120 --size 320x240 "
                                               "--drop-height 0.5 -q -o '" + tmp + "'", &out);
    EXPECT_EQ(rc, 0) << out;
    std::filesystem::rename(tmp, p);
  }
  path = p;
  return path;
}

struct Received {
  std::vector<ball_box_t> boxes;
};

TEST(CaptureNode, PublishesOneBoxPerFrameFromAClip) {
  VideoFileSource source({SynthClip(), false});
  Tracker tracker(TrackerConfig{});
  LcmBus bus("memq://");
  Received rx;
  bus.Subscribe<ball_box_t>("BALL_BOX", [&](const ball_box_t& m) { rx.boxes.push_back(m); });
  CaptureNode node(source, tracker, &bus, {});
  std::vector<BallObservation> seen;
  std::vector<int64_t> frame_times;
  node.set_observer([&](const Frame& f, const BallObservation& o) {
    seen.push_back(o);
    frame_times.push_back(f.utime);
  });
  while (node.Step()) {
    while (bus.HandleOnce(0)) {
    }
  }
  const CaptureStats& s = node.stats();
  EXPECT_EQ(s.frames, 180);
  EXPECT_EQ(s.published, 180);
  ASSERT_EQ(rx.boxes.size(), 180u);
  for (std::size_t i = 0; i < rx.boxes.size(); ++i) {
    EXPECT_EQ(rx.boxes[i].frame, static_cast<int64_t>(i));
    EXPECT_EQ(rx.boxes[i].utime, frame_times[i]);  // the frame's capture time, not wall time
    EXPECT_NEAR(double(rx.boxes[i].utime), i * 1e6 / 120, 1.0);
    EXPECT_EQ(rx.boxes[i].found, seen[i].found);
    EXPECT_EQ(rx.boxes[i].cy, seen[i].cy);
  }
  // The ball is in view: the (automatic) tracker locks on once it moves, and keeps it.
  EXPECT_GT(s.found, 90) << tracker.Describe();
  EXPECT_EQ(s.found, std::count_if(rx.boxes.begin(), rx.boxes.end(),
                                   [](const ball_box_t& b) { return b.found; }));
}

FakeV4l2Script RedSquareCamera(std::vector<FakeV4l2Event> events) {
  FakeV4l2Script s;
  s.formats = FakeV4l2Device::TypicalFormats();
  s.events = std::move(events);
  return s;
}

TEST(CaptureNode, CameraPathRecordsWhatItSawWithTheCameraTiming) {
  const auto dir = testing::ScratchDir("capture_node_record");
  const std::string avi = (dir / "session.avi").string();
  // 40 frames from the (fake) camera, YUYV at 120 fps, with sequence 10-12 dropped.
  FakeV4l2Device dev(RedSquareCamera(FakeV4l2Device::Frames(0, 40, 120, {10, 11, 12}, 7000000)));
  V4l2CameraConfig cc;
  cc.timeout_ms = 100;
  V4l2Camera camera(cc, dev);
  Tracker tracker(TrackerConfig{});
  LcmBus bus("memq://");
  std::vector<ball_box_t> boxes;
  bus.Subscribe<ball_box_t>("BALL_BOX", [&](const ball_box_t& m) { boxes.push_back(m); });
  const std::string log_path = (dir / "session.lcm").string();
  std::vector<int64_t> camera_times;
  {
    FrameRecorder recorder(avi, camera.Info().nominal_fps);
    LcmLogRecorder log(log_path);
    CaptureNode node(camera, tracker, &bus, {});
    node.set_recorder(&recorder);
    node.set_log(&log);
    node.set_observer([&](const Frame& f, const BallObservation&) { camera_times.push_back(f.utime); });
    // The script ends after 40 frames: the camera then times out, like a stalled device.
    EXPECT_THROW(node.Run(), std::runtime_error);
    while (bus.HandleOnce(0)) {
    }
    EXPECT_EQ(node.stats().frames, 40);
    EXPECT_EQ(node.stats().dropped, 3);
    EXPECT_EQ(recorder.written(), 40);
  }
  ASSERT_EQ(boxes.size(), 40u);
  EXPECT_EQ(boxes[10].utime, 7000000 + std::llround(13 * 1e6 / 120));  // driver's clock

  // The log holds the same 40 boxes.
  LcmLogReader reader(log_path);
  int n = 0;
  while (auto e = reader.Next()) {
    ball_box_t m;
    ASSERT_GT(m.decode(e->data.data(), 0, static_cast<int>(e->data.size())), 0);
    EXPECT_EQ(m.utime, boxes[n].utime);
    ++n;
  }
  EXPECT_EQ(n, 40);

  // Replaying the recording gives the camera's frames, times, sequence numbers and drops.
  VideoFileSource replay({avi, false});
  EXPECT_TRUE(replay.uses_times_file());
  std::vector<Frame> frames;
  while (auto f = replay.Next()) frames.push_back(*f);
  ASSERT_EQ(frames.size(), 40u);
  EXPECT_EQ(replay.dropped_frames(), 3);
  for (int i = 0; i < 40; ++i) {
    EXPECT_EQ(frames[i].utime, camera_times[i] - camera_times[0]) << i;
    EXPECT_EQ(frames[i].sequence, i < 10 ? i : i + 3);
    // The picture survived YUYV -> BGR -> MJPEG: the red square is where the camera put it.
    cv::Mat mask;
    cv::inRange(frames[i].image, cv::Scalar(0, 0, 170), cv::Scalar(100, 100, 255), mask);
    const cv::Point want = FakeV4l2Device::SquareCorner(640, 480, frames[i].sequence);
    const cv::Rect got = cv::boundingRect(mask);
    EXPECT_LE(std::abs(got.x - want.x) + std::abs(got.y - want.y), 3) << i;
  }
}

TEST(CaptureNode, CameraVanishingKeepsWhatWasRecorded) {
  const auto dir = testing::ScratchDir("capture_node_enodev");
  const std::string avi = (dir / "cut.avi").string();
  auto events = FakeV4l2Device::Frames(0, 25, 120);
  events.push_back({FakeV4l2Event::kEnodev, 0, 0});
  FakeV4l2Device dev(RedSquareCamera(events));
  V4l2Camera camera(V4l2CameraConfig{}, dev);
  Tracker tracker(TrackerConfig{});
  FrameRecorder recorder(avi, 120);
  CaptureNode node(camera, tracker, nullptr, {});
  node.set_recorder(&recorder);
  try {
    node.Run();
    FAIL() << "expected the camera to vanish";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/dev/video0: the camera vanished (ENODEV) (after 25 frames)");
  }
  recorder.Close();
  EXPECT_EQ(node.stats().frames, 25);
  VideoFileSource replay({avi, false});
  int n = 0;
  while (replay.Next()) ++n;
  EXPECT_EQ(n, 25);
}

TEST(CaptureNode, StopsAtTheStopFlagAndAtMaxFrames) {
  VideoFileSource source({SynthClip(), true});
  Tracker tracker(TrackerConfig{});
  CaptureNodeConfig c;
  c.max_frames = 250;  // more than the clip: it loops
  CaptureNode node(source, tracker, nullptr, c);
  node.Run();
  EXPECT_EQ(node.stats().frames, 250);
  EXPECT_EQ(source.loops_done(), 1);
  std::atomic<bool> stop{true};
  VideoFileSource again({SynthClip(), false});
  CaptureNode stopped(again, tracker, nullptr, {});
  stopped.Run(&stop);
  EXPECT_EQ(stopped.stats().frames, 0);
}

// --- the command ---

TEST(CaptureCommand, ReplaysAClipAsFastAsPossibleAndLogsIt) {
  const auto dir = testing::ScratchDir("capture_command_log");
  const std::string log = (dir / "boxes.lcm").string();
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " capture --replay '" + SynthClip() +
                           "' --speed 0 --lcm-url memq:// --log '" + log + "'",
                       &out),
            0)
      << out;
  EXPECT_NE(out.find("capture: done: 180 frames, 0 dropped"), std::string::npos) << out;
  // Every message it sent: STREAM at the start and the end, a box per frame between them.
  LcmLogReader reader(log);
  std::vector<std::string> channels;
  while (auto e = reader.Next()) channels.push_back(e->channel);
  ASSERT_EQ(channels.size(), 182u);
  EXPECT_EQ(channels.front(), "STREAM");
  EXPECT_EQ(channels.back(), "STREAM");
  EXPECT_EQ(std::count(channels.begin(), channels.end(), "BALL_BOX"), 180);
}

TEST(CaptureCommand, CtrlCStopsCleanlyAndKeepsTheLog) {
  const auto dir = testing::ScratchDir("capture_command_sigint");
  const std::string log = (dir / "boxes.lcm").string();
  std::string out;
  // The 1.5 s clip replayed at half speed (3 s), interrupted 0.5 s after its first box is
  // logged: start-up time on a loaded machine cannot move the stop out of the stream.
  const int rc = RunCommand(
      "bash -c \"" + BouncefitExe() + " capture --replay '" + SynthClip() +
          "' --speed 0.5 --lcm-url memq:// --quiet --log '" + log +
          "' & P=\\$!; for i in \\$(seq 500); do [ -s '" + log +
          "' ] && break; sleep 0.02; done; sleep 0.5; kill -INT \\$P; wait \\$P\"",
      &out);
  EXPECT_EQ(rc, 130) << out;  // stopped by the user, after writing what was recorded
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("capture: stopped: (\\d+) frames"))) << out;
  const int frames = std::stoi(m[1]);
  EXPECT_GT(frames, 20);
  EXPECT_LT(frames, 170);
  // Every box published before the stop is in the log, between STREAM's start and end, and
  // the log is whole.
  LcmLogReader reader(log);
  int n = 0;
  while (reader.Next()) ++n;
  EXPECT_EQ(n, frames + 2);
}

TEST(CaptureCommand, BadInputIsOneLineAndNonZero) {
  const auto dir = testing::ScratchDir("capture_command_errors");
  const std::string exe = BouncefitExe() + " capture ";
  std::string out;
  const std::string missing = (dir / "missing.avi").string();
  EXPECT_EQ(RunCommand(exe + "--replay '" + missing + "' --lcm-url memq://", &out), 1);
  EXPECT_EQ(out, "bouncefit capture: error: cannot open video '" + missing + "': no such file\n");

  const std::string junk = (dir / "junk.avi").string();
  {
    std::ofstream f(junk, std::ios::binary);
    for (int i = 0; i < 50000; ++i) f.put(static_cast<char>((i * 7919) % 251));
  }
  EXPECT_EQ(RunCommand(exe + "--replay '" + junk + "' --lcm-url memq://", &out), 1);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_EQ(out.rfind("bouncefit capture: error: ", 0), 0u) << out;

  EXPECT_EQ(RunCommand(exe + "--device /dev/video-none --lcm-url memq://", &out), 1);
  EXPECT_EQ(out, "bouncefit capture: error: cannot open /dev/video-none: No such file or directory\n");
  EXPECT_EQ(RunCommand(exe + "--lcm-url memq://", &out), 2);
  EXPECT_EQ(out, "bouncefit capture: error: give exactly one of --replay CLIP or --device /dev/videoN\n");
  EXPECT_EQ(RunCommand(exe + "--replay x.avi --speed -2", &out), 2);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_EQ(RunCommand(exe + "--replay x.avi --frobnicate", &out), 2);
  EXPECT_EQ(RunCommand(exe + "--device /dev/video0 --size 640by480 --lcm-url memq://", &out), 2);
}

TEST(CaptureCommand, ListsDevicesOrSaysThereAreNone) {
  std::string out;
  EXPECT_EQ(RunCommand(BouncefitExe() + " capture --list-devices", &out), 0);
  if (std::filesystem::exists("/dev/video0"))
    EXPECT_NE(out.find("/dev/video"), std::string::npos) << out;
  else
    EXPECT_EQ(out, "no V4L2 capture device (/dev/video*) on this machine\n");
  if (!std::filesystem::exists("/dev/video0")) {
    EXPECT_EQ(RunCommand(BouncefitExe() + " capture --list-formats", &out), 1);
    EXPECT_EQ(out, "bouncefit capture: error: cannot open /dev/video0: No such file or directory\n");
  }
}

}  // namespace
}  // namespace bouncefit
