#include "capture/v4l2_device_query.h"

#include <fcntl.h>
#include <linux/videodev2.h>

#include <cerrno>
#include <stdexcept>
#include <utility>

namespace bouncefit {
namespace {

std::string CString(const uint8_t* text, std::size_t max) {
  std::size_t n = 0;
  while (n < max && text[n]) ++n;
  return std::string(reinterpret_cast<const char*>(text), n);
}

std::vector<V4l2Interval> EnumIntervals(V4l2Io& io, int fd, uint32_t fourcc, int w, int h,
                                        bool* range) {
  std::vector<V4l2Interval> out;
  *range = false;
  for (uint32_t i = 0; i < 64; ++i) {
    v4l2_frmivalenum e{};
    e.index = i;
    e.pixel_format = fourcc;
    e.width = static_cast<uint32_t>(w);
    e.height = static_cast<uint32_t>(h);
    if (io.Ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &e) < 0) break;
    if (e.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      out.push_back({e.discrete.numerator, e.discrete.denominator});
    } else {
      out.push_back({e.stepwise.min.numerator, e.stepwise.min.denominator});
      out.push_back({e.stepwise.max.numerator, e.stepwise.max.denominator});
      *range = true;
      break;
    }
  }
  return out;
}

}  // namespace

std::vector<V4l2FormatInfo> EnumerateV4l2Formats(V4l2Io& io, int fd) {
  std::vector<V4l2FormatInfo> formats;
  for (uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (io.Ioctl(fd, VIDIOC_ENUM_FMT, &d) < 0) break;
    V4l2FormatInfo f;
    f.fourcc = d.pixelformat;
    f.description = CString(d.description, sizeof d.description);
    f.compressed = d.flags & V4L2_FMT_FLAG_COMPRESSED;
    for (uint32_t j = 0; j < 256; ++j) {
      v4l2_frmsizeenum s{};
      s.index = j;
      s.pixel_format = d.pixelformat;
      if (io.Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &s) < 0) break;
      if (s.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        V4l2FrameSize size{static_cast<int>(s.discrete.width), static_cast<int>(s.discrete.height), {}, false};
        size.intervals = EnumIntervals(io, fd, d.pixelformat, size.width, size.height,
                                       &size.interval_range);
        f.sizes.push_back(size);
      } else {
        for (auto [w, h] : {std::pair{s.stepwise.min_width, s.stepwise.min_height},
                            std::pair{s.stepwise.max_width, s.stepwise.max_height}}) {
          V4l2FrameSize size{static_cast<int>(w), static_cast<int>(h), {}, false};
          size.intervals = EnumIntervals(io, fd, d.pixelformat, size.width, size.height,
                                         &size.interval_range);
          f.sizes.push_back(size);
        }
        f.size_range = true;
        break;
      }
    }
    formats.push_back(std::move(f));
  }
  return formats;
}

std::string FourccToString(uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    if (c != ' ' && c != '\0') s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

std::optional<V4l2DeviceInfo> QueryV4l2Device(V4l2Io& io, int fd, const std::string& path) {
  v4l2_capability cap{};
  if (io.Ioctl(fd, VIDIOC_QUERYCAP, &cap) < 0) return std::nullopt;
  const uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  return V4l2DeviceInfo{path, CString(cap.card, sizeof cap.card),
                        CString(cap.driver, sizeof cap.driver),
                        CString(cap.bus_info, sizeof cap.bus_info), caps};
}

std::vector<V4l2DeviceInfo> ListV4l2Devices(V4l2Io& io) {
  std::vector<V4l2DeviceInfo> devices;
  for (const auto& path : io.DevicePaths()) {
    const int fd = io.Open(path, O_RDWR | O_NONBLOCK);
    if (fd < 0) {
      devices.push_back({path, "(cannot open: " + V4l2ErrnoText(errno) + ")", "", ""});
      continue;
    }
    auto device = QueryV4l2Device(io, fd, path);
    if (device && (device->capabilities & V4L2_CAP_VIDEO_CAPTURE)) devices.push_back(*device);
    io.Close(fd);
  }
  return devices;
}

std::vector<V4l2FormatInfo> ListV4l2Formats(const std::string& device, V4l2Io& io) {
  const int fd = io.Open(device, O_RDWR | O_NONBLOCK);
  if (fd < 0) throw std::runtime_error("cannot open " + device + ": " + V4l2ErrnoText(errno));
  if (!QueryV4l2Device(io, fd, device)) {
    const int err = errno;
    io.Close(fd);
    throw std::runtime_error(device + " is not a V4L2 device: " + V4l2ErrnoText(err));
  }
  auto formats = EnumerateV4l2Formats(io, fd);
  io.Close(fd);
  return formats;
}

}  // namespace bouncefit
