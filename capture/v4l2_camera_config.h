#pragma once
// What a V4L2 camera is asked for: the device, the size, rate and pixel format to negotiate,
// and how its stream is read.
#include <string>

namespace bouncefit {

struct V4l2CameraConfig {
  std::string device = "/dev/video0";
  int width = 640;           // 0: keep the driver's current size
  int height = 480;
  double fps = 120;          // 0: keep the driver's current frame interval
  // "auto": YUYV when it reaches fps at this size, else MJPEG when that does, else the
  // faster of the two. "yuyv" / "mjpeg": that format or an error.
  std::string pixel_format = "auto";
  int buffers = 4;           // mmap buffers asked of the driver (it may grant more or fewer)
  int timeout_ms = 2000;     // no frame for this long: error
  int max_consecutive_errors = 20;  // EIO / corrupt frames in a row before giving up

  // Throws std::invalid_argument with a one-line reason.
  void Validate() const;
};

}  // namespace bouncefit
