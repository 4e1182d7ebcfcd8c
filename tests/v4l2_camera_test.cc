// The real V4L2 camera code driven by a scripted fake device: negotiation, a driver that
// grants only 60 fps, dropped sequence numbers, EAGAIN, ENODEV mid-stream, clean stop. When a
// real /dev/video* exists the stream checks also run against it.
#include <linux/videodev2.h>

#include <gtest/gtest.h>

#include <chrono>
#include <opencv2/imgproc.hpp>

#include "capture/v4l2_camera.h"
#include "capture/v4l2_device_query.h"
#include "tests/v4l2_fake_device.h"

namespace bouncefit {
namespace {

using Ev = FakeV4l2Event;
using Fake = FakeV4l2Device;

// Where the red square is in a decoded frame (the fake encodes the sequence number there).
cv::Point FindSquare(const Frame& frame) {
  cv::Mat bgr;
  if (frame.format == PixelFormat::kYuyv)
    cv::cvtColor(frame.image, bgr, cv::COLOR_YUV2BGR_YUYV);
  else
    bgr = frame.image;
  cv::Mat mask;
  cv::inRange(bgr, cv::Scalar(0, 0, 170), cv::Scalar(90, 90, 255), mask);
  const cv::Rect box = cv::boundingRect(mask);
  return box.tl();
}

// Checks a stream of n frames from any camera, fake or real: indices count from 0,
// sequence numbers and timestamps increase, drops equal the sequence gaps.
void CheckStream(V4l2Camera& camera, int n) {
  int64_t first_seq = -1, last_seq = -1, last_utime = 0;
  for (int i = 0; i < n; ++i) {
    auto frame = camera.Next();
    ASSERT_TRUE(frame.has_value()) << "frame " << i;
    EXPECT_EQ(frame->index, i);
    EXPECT_EQ(frame->image.cols, camera.negotiated().width);
    EXPECT_EQ(frame->image.rows, camera.negotiated().height);
    EXPECT_EQ(frame->image.type(), frame->format == PixelFormat::kYuyv ? CV_8UC2 : CV_8UC3);
    if (i == 0) {
      first_seq = frame->sequence;
    } else {
      EXPECT_GT(frame->sequence, last_seq);
      EXPECT_GT(frame->utime, last_utime);
    }
    last_seq = frame->sequence;
    last_utime = frame->utime;
  }
  EXPECT_EQ(camera.dropped_frames(), (last_seq - first_seq + 1) - n);
}

TEST(V4l2Camera, NegotiatesYuyvAt120WhenYuyvReachesIt) {
  FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(0, 10, 120)));
  V4l2Camera camera(Fake::CameraConfig(), dev);
  const auto& n = camera.negotiated();
  EXPECT_EQ(n.fourcc, V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(n.width, 640);
  EXPECT_EQ(n.height, 480);
  EXPECT_DOUBLE_EQ(n.interval.fps(), 120.0);
  EXPECT_EQ(dev.interval().denominator, 120u);  // the device really was set to 120
  EXPECT_EQ(dev.fourcc(), V4L2_PIX_FMT_YUYV);
  EXPECT_EQ(n.summary, "/dev/video0 (Fake UVC Camera): YUYV 640x480 at 120.00 fps");
  EXPECT_EQ(camera.Info().nominal_fps, 120.0);
  CheckStream(camera, 10);
  EXPECT_EQ(camera.dropped_frames(), 0);
}

TEST(V4l2Camera, YuyvFramesCarryTheDevicePictureTimestampAndSequence) {
  FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(100, 12, 120, {}, 5000000)));
  V4l2Camera camera(Fake::CameraConfig(), dev);
  for (int i = 0; i < 12; ++i) {
    auto f = camera.Next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->format, PixelFormat::kYuyv);
    EXPECT_EQ(f->sequence, 100 + i);
    EXPECT_EQ(f->utime, 5000000 + std::llround(i * 1e6 / 120));  // the driver's clock
    EXPECT_EQ(FindSquare(*f), Fake::SquareCorner(640, 480, 100 + i));
  }
}

TEST(V4l2Camera, ChoosesMjpegWhereOnlyMjpegReachesTheRateAndDecodesIt) {
  FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(0, 5, 120)));
  V4l2Camera camera(Fake::CameraConfig(1280, 720, 120), dev);
  EXPECT_EQ(camera.negotiated().fourcc, V4L2_PIX_FMT_MJPEG);
  EXPECT_EQ(camera.negotiated().width, 1280);
  EXPECT_DOUBLE_EQ(camera.negotiated().interval.fps(), 120.0);
  EXPECT_NE(camera.negotiated().summary.find("YUYV reaches only 30.00 fps"), std::string::npos)
      << camera.negotiated().summary;
  for (int i = 0; i < 5; ++i) {
    auto f = camera.Next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->format, PixelFormat::kBgr24);
    EXPECT_EQ(f->image.type(), CV_8UC3);
    EXPECT_EQ(f->image.size(), cv::Size(1280, 720));
    const cv::Point c = FindSquare(*f), want = Fake::SquareCorner(1280, 720, i);
    EXPECT_LE(std::abs(c.x - want.x) + std::abs(c.y - want.y), 2);
  }
}

TEST(V4l2Camera, SaysPlainlyWhenTheDriverGrantsOnly60Fps) {
  FakeV4l2Script s = Fake::TypicalScript(Fake::Frames(0, 6, 60));
  s.grant_only = V4l2Interval{1, 60};
  FakeV4l2Device dev(s);
  V4l2Camera camera(Fake::CameraConfig(), dev);
  EXPECT_DOUBLE_EQ(camera.negotiated().interval.fps(), 60.0);
  EXPECT_EQ(camera.Info().nominal_fps, 60.0);
  EXPECT_EQ(camera.negotiated().summary,
            "/dev/video0 (Fake UVC Camera): YUYV 640x480 at 60.00 fps (asked 120.00 fps: the "
            "driver granted 60.00)");
  CheckStream(camera, 6);
}

TEST(V4l2Camera, UsesSeveralMmapBuffersAndRequeuesThem) {
  FakeV4l2Script s = Fake::TypicalScript(Fake::Frames(0, 50, 120));
  s.max_buffers = 3;  // fewer than asked: 50 frames through 3 buffers needs requeueing
  FakeV4l2Device dev(s);
  auto c = Fake::CameraConfig();
  c.buffers = 6;
  V4l2Camera camera(c, dev);
  EXPECT_EQ(dev.requested_buffers(), 6);
  EXPECT_EQ(camera.negotiated().buffers, 3);
  EXPECT_EQ(dev.mapped(), 3);
  EXPECT_TRUE(dev.streaming());
  CheckStream(camera, 50);
  EXPECT_EQ(dev.misuse(), "");
}

TEST(V4l2Camera, CountsDroppedSequenceNumbers) {
  // The driver skipped sequence numbers 3, 4, 9 and 20..24: 8 frames lost.
  FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(0, 30, 120, {3, 4, 9, 20, 21, 22, 23, 24})));
  V4l2Camera camera(Fake::CameraConfig(), dev);
  std::vector<int64_t> seqs;
  while (seqs.size() < 30) {
    auto f = camera.Next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->index, static_cast<int64_t>(seqs.size()));
    seqs.push_back(f->sequence);
    if (seqs.size() == 5) {
      EXPECT_EQ(camera.dropped_frames(), 2);  // after 0 1 2 5 6
    }
  }
  EXPECT_EQ(seqs[3], 5);
  EXPECT_EQ(camera.dropped_frames(), 8);
}

TEST(V4l2Camera, FlaggedAndCorruptFramesAreSkippedAndCountedAsDropped) {
  auto events = Fake::Frames(0, 4, 120);
  events.insert(events.begin() + 2, {Ev::kErrorFrame, 2, 0});
  events.insert(events.begin() + 3, {Ev::kCorruptFrame, 3, 0});
  for (std::size_t i = 4; i < events.size(); ++i) events[i].sequence += 2;
  FakeV4l2Device dev(Fake::TypicalScript(events));
  V4l2Camera camera(Fake::CameraConfig(), dev);
  std::vector<int64_t> seqs;
  for (int i = 0; i < 4; ++i) seqs.push_back(camera.Next()->sequence);
  EXPECT_EQ(seqs, (std::vector<int64_t>{0, 1, 4, 5}));
  EXPECT_EQ(camera.dropped_frames(), 2);
  EXPECT_EQ(camera.error_frames(), 2);
}

TEST(V4l2Camera, EagainAndEioAreRetriedWithoutLosingFrames) {
  auto events = Fake::Frames(0, 8, 120);
  std::vector<FakeV4l2Event> script;
  for (std::size_t i = 0; i < events.size(); ++i) {
    script.push_back({Ev::kEagain, 0, 0});
    if (i % 3 == 0) script.push_back({Ev::kEagain, 0, 0});
    if (i == 5) script.push_back({Ev::kEio, 0, 0});
    script.push_back(events[i]);
  }
  FakeV4l2Device dev(Fake::TypicalScript(script));
  V4l2Camera camera(Fake::CameraConfig(), dev);
  CheckStream(camera, 8);
  EXPECT_EQ(camera.eagain_count(), 11);
  EXPECT_EQ(camera.dropped_frames(), 0);
  EXPECT_EQ(dev.events_left(), 0);
}

TEST(V4l2Camera, EnodevMidStreamIsAClearErrorAndKeepsWhatWasCaptured) {
  auto events = Fake::Frames(0, 5, 120, {2});
  events.push_back({Ev::kEnodev, 0, 0});
  FakeV4l2Device dev(Fake::TypicalScript(events));
  std::vector<Frame> kept;
  {
    V4l2Camera camera(Fake::CameraConfig(), dev);
    for (int i = 0; i < 5; ++i) kept.push_back(*camera.Next());
    try {
      camera.Next();
      FAIL() << "expected ENODEV";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "/dev/video0: the camera vanished (ENODEV) (after 5 frames)");
    }
    EXPECT_EQ(camera.dropped_frames(), 1);
    EXPECT_THROW(camera.Next(), std::runtime_error);  // stays failed, no hang
  }
  // Clean-up still happened: nothing mapped, nothing open.
  EXPECT_EQ(dev.mapped(), 0);
  EXPECT_EQ(dev.open_fds(), 0);
  // The frames captured before the camera vanished are intact.
  ASSERT_EQ(kept.size(), 5u);
  EXPECT_EQ(kept[4].sequence, 5);
  EXPECT_EQ(FindSquare(kept[4]), Fake::SquareCorner(640, 480, 5));
}

TEST(V4l2Camera, NoFrameWithinTheTimeoutIsAnError) {
  FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(0, 2, 120)));
  V4l2Camera camera(Fake::CameraConfig(), dev);
  camera.Next();
  camera.Next();
  try {
    camera.Next();
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/dev/video0: no frame for 0.2 s (after 2 frames)");
  }
}

TEST(V4l2Camera, ADriverStuckOnEagainIsAnErrorNotASpin) {
  FakeV4l2Script s = Fake::TypicalScript(Fake::Frames(0, 3, 120));
  s.stuck_after_events = true;  // poll: ready; DQBUF: EAGAIN, forever
  FakeV4l2Device dev(s);
  V4l2Camera camera(Fake::CameraConfig(), dev);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(camera.Next());
  const auto t0 = std::chrono::steady_clock::now();
  try {
    camera.Next();
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "/dev/video0: no frame for 0.2 s, the driver only says EAGAIN (after 3 frames)");
  }
  const double s_waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GT(s_waited, 0.19);
  EXPECT_LT(s_waited, 1.0);
}

TEST(V4l2Camera, StopsCleanly) {
  FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(0, 3, 120)));
  V4l2Camera camera(Fake::CameraConfig(), dev);
  camera.Next();
  camera.Stop();
  EXPECT_EQ(dev.streamoff_calls(), 1);
  EXPECT_FALSE(dev.streaming());
  EXPECT_EQ(dev.mapped(), 0);
  EXPECT_EQ(dev.granted_buffers(), 0);
  EXPECT_EQ(dev.open_fds(), 0);
  EXPECT_FALSE(camera.Next().has_value());
  camera.Stop();  // idempotent
  EXPECT_EQ(dev.streamoff_calls(), 1);
  EXPECT_EQ(dev.misuse(), "");
}

TEST(V4l2Camera, ReadIoFallbackWhenTheDriverCannotStream) {
  FakeV4l2Script s = Fake::TypicalScript(Fake::Frames(0, 3, 120));
  s.streaming = false;
  FakeV4l2Device dev(s);
  V4l2Camera camera(Fake::CameraConfig(), dev);
  EXPECT_FALSE(camera.negotiated().streaming);
  for (int i = 0; i < 3; ++i) {
    auto f = camera.Next();
    ASSERT_TRUE(f);
    EXPECT_EQ(FindSquare(*f), Fake::SquareCorner(640, 480, i));
  }
}

TEST(V4l2Camera, MissingDeviceIsAOneLineError) {
  auto c = Fake::CameraConfig();
  c.device = "/dev/video-does-not-exist";
  try {
    V4l2Camera camera(c);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "cannot open /dev/video-does-not-exist: No such file or directory");
  }
}

// The same stream checks against every real capture device on this machine.
TEST(V4l2Camera, RealDevicesWhenPresent) {
  const auto devices = ListV4l2Devices();
  int tried = 0;
  for (const auto& d : devices) {
    if (d.driver.empty()) continue;  // could not open it
    SCOPED_TRACE(d.path + " " + d.card);
    V4l2CameraConfig c;
    c.device = d.path;
    c.fps = 30;
    c.timeout_ms = 3000;
    V4l2Camera camera(c);
    std::printf("real device: %s\n", camera.negotiated().summary.c_str());
    CheckStream(camera, 30);
    camera.Stop();
    ++tried;
  }
  if (tried == 0) GTEST_SKIP() << "no /dev/video* capture device on this machine";
}

}  // namespace
}  // namespace bouncefit
