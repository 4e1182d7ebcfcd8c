#include "capture/v4l2_camera_config.h"

#include <stdexcept>

namespace bouncefit {

void V4l2CameraConfig::Validate() const {
  if (device.empty()) throw std::invalid_argument("no camera device given");
  if (width < 0 || height < 0 || (width == 0) != (height == 0))
    throw std::invalid_argument("frame size must be WIDTHxHEIGHT with both positive");
  if (!(fps >= 0) || fps > 10000) throw std::invalid_argument("--fps must be in [0, 10000]");
  if (pixel_format != "auto" && pixel_format != "yuyv" && pixel_format != "mjpeg")
    throw std::invalid_argument("pixel format must be auto, yuyv or mjpeg, not '" +
                                pixel_format + "'");
  if (buffers < 2 || buffers > 32) throw std::invalid_argument("buffers must be in [2, 32]");
  if (timeout_ms <= 0) throw std::invalid_argument("timeout must be positive");
}

}  // namespace bouncefit
