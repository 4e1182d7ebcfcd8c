// The capture stage (pipeline/capture_stage.h): a clip or the (fake) camera in; STREAM, one
// BALL_BOX per frame and the impacts heard out on the bus, and the files it owns (track.csv,
// session.lcm); --record keeps the camera's timing; a failing camera keeps what was captured.
#include "pipeline/capture_stage.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/impact_t.hpp"
#include "bouncefit/stream_t.hpp"
#include "msgs/lcm_bus.h"
#include "pipeline/lcm_log_replay.h"
#include "replay/video_file_source.h"
#include "tests/test_support.h"
#include "tests/v4l2_fake_device.h"

namespace bouncefit {
namespace {

// What the stage sent on the bus, in order.
struct Heard {
  std::vector<stream_t> streams;
  std::vector<ball_box_t> boxes;
  std::vector<impact_t> impacts;
  std::vector<std::string> channels;
  explicit Heard(LcmBus& bus) {
    bus.Subscribe<stream_t>("STREAM", [this](const stream_t& m) { streams.push_back(m), channels.push_back("STREAM"); });
    bus.Subscribe<ball_box_t>("BALL_BOX", [this](const ball_box_t& m) { boxes.push_back(m), channels.push_back("BALL_BOX"); });
    bus.Subscribe<impact_t>("IMPACT", [this](const impact_t& m) { impacts.push_back(m), channels.push_back("IMPACT"); });
  }
};

CaptureStageConfig ShortClipAsFastAsPossible() {
  CaptureStageConfig c;
  c.clip = testing::ShortDropClip();
  c.camera.device.clear();  // a clip, not the default camera
  c.speed = 0;
  return c;
}

TEST(CaptureStage, AClipInStreamBoxesAndItsFilesOut) {
  const auto dir = testing::ScratchDir("out");
  LcmBus bus("memq://");
  Heard heard(bus);
  CaptureStageConfig c = ShortClipAsFastAsPossible();
  c.out_dir = dir;
  CaptureStage stage(c, bus);
  EXPECT_EQ(stage.stream().width, 320);
  EXPECT_EQ(stage.stream().height, 240);
  std::vector<int64_t> frame_times;
  stage.set_frame_observer([&](const Frame& f, const BallObservation&) { frame_times.push_back(f.utime); });
  while (stage.Step()) bus.Drain();
  stage.End(false);
  bus.Drain();
  EXPECT_EQ(stage.failure(), "");

  // STREAM at the start and at the end, a box per frame between them, in frame order.
  ASSERT_EQ(heard.streams.size(), 2u);
  EXPECT_EQ(heard.streams[0].state, "start");
  EXPECT_EQ(heard.streams[1].state, "end");
  EXPECT_EQ(heard.channels.front(), "STREAM");
  EXPECT_EQ(heard.channels.back(), "STREAM");
  const stream_t& end = heard.streams[1];
  EXPECT_EQ(end.frames, 180);
  EXPECT_EQ(stage.frames(), 180);
  ASSERT_EQ(heard.boxes.size(), 180u);
  for (std::size_t i = 0; i < heard.boxes.size(); ++i) {
    EXPECT_EQ(heard.boxes[i].frame, static_cast<int64_t>(i));
    EXPECT_EQ(heard.boxes[i].utime, frame_times[i]);  // the frame's capture time, not wall time
    EXPECT_NEAR(double(heard.boxes[i].utime), i * 1e6 / 120, 1.0);
  }
  // The ball is in view: the (automatic) tracker locks on once it moves, and keeps it.
  EXPECT_GT(end.found, 90) << end.tracker;
  EXPECT_EQ(end.found, std::count_if(heard.boxes.begin(), heard.boxes.end(), [](const ball_box_t& b) { return b.found; }));
  EXPECT_EQ(stage.found(), end.found);

  // track.csv: a row per box, the ball where the box says.
  const auto rows = testing::ReadCsv(dir / "track.csv");
  ASSERT_EQ(rows.size(), 180u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].at("frame"), std::to_string(i));
    EXPECT_EQ(rows[i].at("found"), heard.boxes[i].found ? "1" : "0");
    if (heard.boxes[i].found) {
      EXPECT_NEAR(std::stod(rows[i].at("cy_px")), heard.boxes[i].cy, 0.001) << i;
    }
  }
  // session.lcm: every message the stage sent, in the order it sent them.
  LcmLogReader reader((dir / "session.lcm").string());
  std::vector<std::string> logged;
  while (auto e = reader.Next()) logged.push_back(e->channel);
  EXPECT_EQ(logged, heard.channels);
}

FakeV4l2Script RedSquareCamera(std::vector<FakeV4l2Event> events) {
  FakeV4l2Script s;
  s.formats = FakeV4l2Device::TypicalFormats();
  s.events = std::move(events);
  return s;
}

TEST(CaptureStage, CameraRecordsWhatItSawWithTheCameraTiming) {
  const auto dir = testing::ScratchDir("record");
  const std::string avi = (dir / "session.avi").string();
  // 40 frames from the (fake) camera, YUYV at 120 fps, with sequence 10-12 dropped.
  FakeV4l2Device dev(RedSquareCamera(FakeV4l2Device::Frames(0, 40, 120, {10, 11, 12}, 7000000)));
  LcmBus bus("memq://");
  Heard heard(bus);
  CaptureStageConfig c;
  c.camera.device = "/dev/video0";
  c.camera.timeout_ms = 100;
  c.camera_io = &dev;
  c.record = avi;
  c.out_dir = dir;
  std::vector<int64_t> camera_times;
  {
    CaptureStage stage(c, bus);
    stage.set_frame_observer([&](const Frame& f, const BallObservation&) { camera_times.push_back(f.utime); });
    // The script ends after 40 frames: the camera then times out, like a stalled device.
    while (stage.Step()) bus.Drain();
    EXPECT_NE(stage.failure(), "");
    stage.End(false);
    bus.Drain();
    EXPECT_EQ(stage.end_message().frames, 40);
    EXPECT_EQ(stage.end_message().dropped, 3);
    EXPECT_EQ(stage.end_message().failure, stage.failure());
  }
  ASSERT_EQ(heard.boxes.size(), 40u);
  EXPECT_EQ(heard.boxes[10].utime, 7000000 + std::llround(13 * 1e6 / 120));  // the driver's clock

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

TEST(CaptureStage, CameraVanishingKeepsWhatWasRecorded) {
  const auto dir = testing::ScratchDir("enodev");
  const std::string avi = (dir / "cut.avi").string();
  auto events = FakeV4l2Device::Frames(0, 25, 120);
  events.push_back({FakeV4l2Event::kEnodev, 0, 0});
  FakeV4l2Device dev(RedSquareCamera(events));
  LcmBus bus("memq://");
  Heard heard(bus);
  CaptureStageConfig c;
  c.camera.device = "/dev/video0";
  c.camera_io = &dev;
  c.record = avi;
  {
    CaptureStage stage(c, bus);
    while (stage.Step()) bus.Drain();
    stage.End(false);
    bus.Drain();
    EXPECT_EQ(stage.failure(), "/dev/video0: the camera vanished (ENODEV) (after 25 frames)");
    ASSERT_EQ(heard.streams.size(), 2u);
    EXPECT_EQ(heard.streams[1].failure, stage.failure());
  }
  EXPECT_EQ(heard.boxes.size(), 25u);
  VideoFileSource replay({avi, false});
  int n = 0;
  while (replay.Next()) ++n;
  EXPECT_EQ(n, 25);
}

TEST(CaptureStage, StopsAtMaxFramesLoopingAClip) {
  LcmBus bus("memq://");
  Heard heard(bus);
  CaptureStageConfig c = ShortClipAsFastAsPossible();
  c.loop = true;
  c.max_frames = 250;  // more than the clip: it loops
  CaptureStage stage(c, bus);
  while (stage.Step()) bus.Drain();
  stage.End(false);
  bus.Drain();
  EXPECT_EQ(stage.frames(), 250);
  EXPECT_EQ(heard.boxes.size(), 250u);
  EXPECT_FALSE(heard.streams.back().stopped);
}

}  // namespace
}  // namespace bouncefit
