// What a device offers (capture/v4l2_device_query.h), read from the scripted fake device:
// the capture devices and each one's formats, sizes and frame intervals.
#include <gtest/gtest.h>

#include "capture/v4l2_device_query.h"
#include "tests/v4l2_fake_device.h"

namespace bouncefit {
namespace {

using Fake = FakeV4l2Device;

TEST(V4l2Camera, ListsDevicesAndFormats) {
  FakeV4l2Device dev(Fake::TypicalScript({}));
  const auto devices = ListV4l2Devices(dev);
  ASSERT_EQ(devices.size(), 1u);
  EXPECT_EQ(devices[0].path, "/dev/video0");
  EXPECT_EQ(devices[0].card, "Fake UVC Camera");
  EXPECT_EQ(devices[0].driver, "uvcvideo");
  const auto formats = ListV4l2Formats("/dev/video0", dev);
  ASSERT_EQ(formats.size(), 2u);
  EXPECT_EQ(FourccToString(formats[0].fourcc), "YUYV");
  EXPECT_EQ(FourccToString(formats[1].fourcc), "MJPG");
  EXPECT_TRUE(formats[1].compressed);
  ASSERT_EQ(formats[0].sizes.size(), 2u);
  EXPECT_EQ(formats[0].sizes[1].width, 1280);
  ASSERT_EQ(formats[0].sizes[1].intervals.size(), 2u);
  EXPECT_DOUBLE_EQ(formats[0].sizes[1].intervals[0].fps(), 30.0);
  EXPECT_EQ(dev.open_fds(), 0);
}

}  // namespace
}  // namespace bouncefit
