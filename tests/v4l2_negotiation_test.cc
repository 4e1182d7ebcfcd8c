// Choosing and setting what the camera streams (capture/v4l2_negotiation.h), reached as
// callers reach it, by opening a V4l2Camera on the scripted fake device: the format kept when
// it reaches the asked rate, a forced format honoured or refused, a driver that cannot set
// the rate or the size said so in the summary line.
#include <linux/videodev2.h>

#include <gtest/gtest.h>

#include "capture/v4l2_camera.h"
#include "capture/v4l2_negotiation.h"
#include "tests/v4l2_fake_device.h"

namespace bouncefit {
namespace {

using Fake = FakeV4l2Device;

TEST(V4l2Camera, KeepsYuyvAt30WhenThatIsAllAsked) {
  FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(0, 2, 30)));
  V4l2Camera camera(Fake::CameraConfig(1280, 720, 30), dev);
  EXPECT_EQ(camera.negotiated().fourcc, V4L2_PIX_FMT_YUYV);
  EXPECT_DOUBLE_EQ(camera.negotiated().interval.fps(), 30.0);
}

TEST(V4l2Camera, ForcedFormatIsHonouredOrRefusedClearly) {
  {
    FakeV4l2Device dev(Fake::TypicalScript(Fake::Frames(0, 2, 120)));
    auto c = Fake::CameraConfig();
    c.pixel_format = "mjpeg";
    V4l2Camera camera(c, dev);
    EXPECT_EQ(camera.negotiated().fourcc, V4L2_PIX_FMT_MJPEG);
  }
  FakeV4l2Script s = Fake::TypicalScript({});
  s.formats.erase(s.formats.begin() + 1);  // YUYV only
  FakeV4l2Device dev(s);
  auto c = Fake::CameraConfig();
  c.pixel_format = "mjpeg";
  try {
    V4l2Camera camera(c, dev);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/dev/video0 (Fake UVC Camera) does not offer MJPEG (offers YUYV)");
  }
  EXPECT_EQ(dev.open_fds(), 0);
}

TEST(V4l2Camera, SaysWhenTheDriverCannotSetTheRateOrTheSize) {
  FakeV4l2Script s = Fake::TypicalScript(Fake::Frames(0, 2, 30));
  s.timeperframe = false;
  FakeV4l2Device dev(s);
  V4l2Camera camera(Fake::CameraConfig(800, 600, 120), dev);
  EXPECT_FALSE(camera.negotiated().interval_settable);
  const std::string& m = camera.negotiated().summary;
  EXPECT_NE(m.find("the driver cannot set the frame rate"), std::string::npos) << m;
  EXPECT_NE(m.find("asked 800x600: the driver gave 640x480"), std::string::npos) << m;
}

}  // namespace
}  // namespace bouncefit
