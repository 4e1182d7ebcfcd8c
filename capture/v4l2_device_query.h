#pragma once
// What a V4L2 device offers: the capture devices on this machine, and each one's formats,
// frame sizes and frame intervals (for `capture --list-devices/--list-formats` and for the
// camera's negotiation). Every system call goes through V4l2Io.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "capture/v4l2_io.h"

namespace bouncefit {

// One frame interval, seconds = numerator / denominator.
struct V4l2Interval {
  uint32_t numerator = 0;
  uint32_t denominator = 0;
  double fps() const { return numerator ? double(denominator) / numerator : 0.0; }
};

struct V4l2FrameSize {
  int width = 0;
  int height = 0;
  std::vector<V4l2Interval> intervals;  // discrete ones; for a range, its two ends
  bool interval_range = false;          // intervals = {fastest, slowest}, any in between
};

struct V4l2FormatInfo {
  uint32_t fourcc = 0;
  std::string description;
  bool compressed = false;
  std::vector<V4l2FrameSize> sizes;  // discrete sizes; for a range, its two ends
  bool size_range = false;
};

struct V4l2DeviceInfo {
  std::string path;
  std::string card;
  std::string driver;
  std::string bus_info;
  uint32_t capabilities = 0;  // V4L2_CAP_* of this node (device_caps where the driver has them)
};

std::string FourccToString(uint32_t fourcc);

// Capture devices (nodes that can capture video), in device-number order.
std::vector<V4l2DeviceInfo> ListV4l2Devices(V4l2Io& io = SystemV4l2Io());
// Formats, frame sizes and frame intervals a device offers. Throws std::runtime_error.
std::vector<V4l2FormatInfo> ListV4l2Formats(const std::string& device,
                                            V4l2Io& io = SystemV4l2Io());

// The same two on a device already open as fd. QueryV4l2Device: nullopt, errno set, when
// VIDIOC_QUERYCAP fails (not a V4L2 device).
std::optional<V4l2DeviceInfo> QueryV4l2Device(V4l2Io& io, int fd, const std::string& path);
std::vector<V4l2FormatInfo> EnumerateV4l2Formats(V4l2Io& io, int fd);

}  // namespace bouncefit
