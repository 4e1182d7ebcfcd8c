#pragma once
// Choosing and setting what a V4L2 camera streams: the pixel format (YUYV or MJPEG, by the
// rate each reaches at the asked size), the frame size and the frame interval, and one line
// that says what was asked and what the driver granted.
#include <cstdint>
#include <string>

#include "capture/v4l2_camera_config.h"
#include "capture/v4l2_device_query.h"
#include "capture/v4l2_io.h"

namespace bouncefit {

// What the driver granted.
struct V4l2Negotiated {
  uint32_t fourcc = 0;
  int width = 0;
  int height = 0;
  int bytes_per_line = 0;
  uint32_t size_image = 0;
  V4l2Interval interval;
  bool interval_settable = false;  // driver supports V4L2_CAP_TIMEPERFRAME
  int buffers = 0;                 // set by the camera when it maps them
  bool streaming = true;           // false: read() I/O
  // One line: "/dev/video0 (UVC Camera): YUYV 640x480 at 60.00 fps (asked 120 fps: the
  // driver granted 60.00)".
  std::string summary;
};

// Negotiates format, size and frame interval on the device open as fd, as config asks,
// filling *negotiated as it goes: after a throw (std::runtime_error, a one-line reason) it
// still says whether the device streams, which the camera's clean-up needs.
void NegotiateV4l2Format(V4l2Io& io, int fd, const V4l2CameraConfig& config,
                         V4l2Negotiated* negotiated);

}  // namespace bouncefit
