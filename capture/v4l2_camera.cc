#include "capture/v4l2_camera.h"

#include <fmt/format.h>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace bouncefit {
namespace {

std::string ErrnoText(int err) {
  if (err == ENODEV) return "No such device (ENODEV)";
  if (err == EAGAIN) return "Resource temporarily unavailable (EAGAIN)";
  return std::strerror(err);
}

std::string CString(const uint8_t* text, std::size_t max) {
  std::size_t n = 0;
  while (n < max && text[n]) ++n;
  return std::string(reinterpret_cast<const char*>(text), n);
}

bool IsMjpeg(uint32_t fourcc) {
  return fourcc == V4L2_PIX_FMT_MJPEG || fourcc == V4L2_PIX_FMT_JPEG;
}

bool Supported(uint32_t fourcc) { return fourcc == V4L2_PIX_FMT_YUYV || IsMjpeg(fourcc); }

uint32_t DeviceCaps(const v4l2_capability& cap) {
  return (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
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

std::vector<V4l2FormatInfo> EnumFormats(V4l2Io& io, int fd) {
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

// The fastest frame rate the format offers at the size nearest to w x h (0: unknown).
double BestFps(const V4l2FormatInfo& f, int w, int h) {
  const V4l2FrameSize* best = nullptr;
  long best_distance = std::numeric_limits<long>::max();
  for (const auto& s : f.sizes) {
    const long distance = (w > 0 && h > 0) ? std::labs(long(s.width) - w) + std::labs(long(s.height) - h) : 0;
    if (distance < best_distance) {
      best_distance = distance;
      best = &s;
    }
  }
  if (!best) return 0;
  double fps = 0;
  for (const auto& i : best->intervals) fps = std::max(fps, i.fps());
  return fps;
}

}  // namespace

std::string FourccToString(uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    if (c != ' ' && c != '\0') s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

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

std::vector<V4l2DeviceInfo> ListV4l2Devices(V4l2Io& io) {
  std::vector<V4l2DeviceInfo> devices;
  for (const auto& path : io.DevicePaths()) {
    const int fd = io.Open(path, O_RDWR | O_NONBLOCK);
    if (fd < 0) {
      devices.push_back({path, "(cannot open: " + ErrnoText(errno) + ")", "", ""});
      continue;
    }
    v4l2_capability cap{};
    if (io.Ioctl(fd, VIDIOC_QUERYCAP, &cap) == 0 && (DeviceCaps(cap) & V4L2_CAP_VIDEO_CAPTURE)) {
      devices.push_back({path, CString(cap.card, sizeof cap.card),
                         CString(cap.driver, sizeof cap.driver),
                         CString(cap.bus_info, sizeof cap.bus_info)});
    }
    io.Close(fd);
  }
  return devices;
}

std::vector<V4l2FormatInfo> ListV4l2Formats(const std::string& device, V4l2Io& io) {
  const int fd = io.Open(device, O_RDWR | O_NONBLOCK);
  if (fd < 0) throw std::runtime_error("cannot open " + device + ": " + ErrnoText(errno));
  v4l2_capability cap{};
  if (io.Ioctl(fd, VIDIOC_QUERYCAP, &cap) < 0) {
    const int err = errno;
    io.Close(fd);
    throw std::runtime_error(device + " is not a V4L2 device: " + ErrnoText(err));
  }
  auto formats = EnumFormats(io, fd);
  io.Close(fd);
  return formats;
}

V4l2Camera::V4l2Camera(V4l2CameraConfig config, V4l2Io& io)
    : config_(std::move(config)), io_(io) {
  config_.Validate();
  fd_ = io_.Open(config_.device, O_RDWR | O_NONBLOCK);
  if (fd_ < 0) throw std::runtime_error("cannot open " + config_.device + ": " + ErrnoText(errno));
  try {
    Negotiate();
    StartStreaming();
  } catch (...) {
    Stop();
    throw;
  }
}

V4l2Camera::~V4l2Camera() { Stop(); }

void V4l2Camera::Fail(const std::string& what, int err) {
  failed_ = true;
  const std::string after = " (after " + std::to_string(delivered_) + " frames)";
  if (err == ENODEV)
    throw std::runtime_error(config_.device + ": the camera vanished (ENODEV)" + after);
  throw std::runtime_error(config_.device + ": " + what + ": " + ErrnoText(err) + after);
}

uint32_t V4l2Camera::ChooseFormat(const std::vector<V4l2FormatInfo>& formats) {
  const V4l2FormatInfo* yuyv = nullptr;
  const V4l2FormatInfo* mjpeg = nullptr;
  std::string offered;
  for (const auto& f : formats) {
    offered += (offered.empty() ? "" : ", ") + FourccToString(f.fourcc);
    if (f.fourcc == V4L2_PIX_FMT_YUYV && !yuyv) yuyv = &f;
    if (IsMjpeg(f.fourcc) && !mjpeg) mjpeg = &f;
  }
  if (offered.empty()) offered = "nothing";
  const std::string where = config_.device + " (" + card_ + ")";
  if (config_.pixel_format == "yuyv") {
    if (!yuyv) throw std::runtime_error(where + " does not offer YUYV (offers " + offered + ")");
    return yuyv->fourcc;
  }
  if (config_.pixel_format == "mjpeg") {
    if (!mjpeg) throw std::runtime_error(where + " does not offer MJPEG (offers " + offered + ")");
    return mjpeg->fourcc;
  }
  if (!yuyv && !mjpeg)
    throw std::runtime_error(where + " offers neither YUYV nor MJPEG (offers " + offered + ")");
  if (!mjpeg) return yuyv->fourcc;
  if (!yuyv) return mjpeg->fourcc;
  const double yuyv_fps = BestFps(*yuyv, config_.width, config_.height);
  const double mjpeg_fps = BestFps(*mjpeg, config_.width, config_.height);
  if (config_.fps <= 0 || yuyv_fps <= 0) return yuyv->fourcc;  // unknown: prefer YUYV
  if (yuyv_fps >= config_.fps * 0.99) return yuyv->fourcc;
  if (mjpeg_fps >= config_.fps * 0.99 || mjpeg_fps > yuyv_fps) {
    format_reason_ = fmt::format("YUYV reaches only {:.2f} fps at this size", yuyv_fps);
    return mjpeg->fourcc;
  }
  return yuyv->fourcc;
}

void V4l2Camera::Negotiate() {
  v4l2_capability cap{};
  if (io_.Ioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0)
    throw std::runtime_error(config_.device + " is not a V4L2 device: " + ErrnoText(errno));
  card_ = CString(cap.card, sizeof cap.card);
  const uint32_t caps = DeviceCaps(cap);
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
    throw std::runtime_error(config_.device + " (" + card_ + ") is not a video capture device");
  if (caps & V4L2_CAP_STREAMING) {
    negotiated_.streaming = true;
  } else if (caps & V4L2_CAP_READWRITE) {
    negotiated_.streaming = false;
  } else {
    throw std::runtime_error(config_.device + " supports neither streaming nor read() I/O");
  }

  const uint32_t fourcc = ChooseFormat(EnumFormats(io_, fd_));

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_.Ioctl(fd_, VIDIOC_G_FMT, &fmt) < 0)
    throw std::runtime_error(config_.device + ": VIDIOC_G_FMT failed: " + ErrnoText(errno));
  if (config_.width > 0) {
    fmt.fmt.pix.width = static_cast<uint32_t>(config_.width);
    fmt.fmt.pix.height = static_cast<uint32_t>(config_.height);
  }
  fmt.fmt.pix.pixelformat = fourcc;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = 0;  // let the driver choose the stride
  fmt.fmt.pix.sizeimage = 0;
  if (io_.Ioctl(fd_, VIDIOC_S_FMT, &fmt) < 0)
    throw std::runtime_error(config_.device + ": cannot set format " + FourccToString(fourcc) +
                             ": " + ErrnoText(errno));
  const uint32_t got = fmt.fmt.pix.pixelformat;
  if (!Supported(got))
    throw std::runtime_error(config_.device + ": asked for " + FourccToString(fourcc) +
                             ", the driver set " + FourccToString(got) +
                             ", which bouncefit cannot read");
  negotiated_.fourcc = got;
  negotiated_.width = static_cast<int>(fmt.fmt.pix.width);
  negotiated_.height = static_cast<int>(fmt.fmt.pix.height);
  negotiated_.bytes_per_line = static_cast<int>(fmt.fmt.pix.bytesperline);
  if (got == V4L2_PIX_FMT_YUYV && negotiated_.bytes_per_line < 2 * negotiated_.width)
    negotiated_.bytes_per_line = 2 * negotiated_.width;
  negotiated_.size_image = fmt.fmt.pix.sizeimage;
  if (negotiated_.size_image == 0)
    negotiated_.size_image = static_cast<uint32_t>(negotiated_.bytes_per_line) *
                             static_cast<uint32_t>(negotiated_.height);
  if (negotiated_.width <= 0 || negotiated_.height <= 0)
    throw std::runtime_error(config_.device + ": the driver set an empty frame size");

  SetFrameInterval();

  // The one line that says plainly what was asked and what was granted.
  std::ostringstream s;
  s << config_.device << " (" << card_ << "): " << FourccToString(got) << " "
    << negotiated_.width << "x" << negotiated_.height << " at "
    << (negotiated_.interval.fps() > 0 ? fmt::format("{:.2f} fps", negotiated_.interval.fps())
                                       : std::string("an unknown rate"));
  std::vector<std::string> notes;
  if (config_.fps > 0) {
    if (!negotiated_.interval_settable)
      notes.push_back(fmt::format("asked {:.2f} fps: the driver cannot set the frame rate", config_.fps));
    else if (std::fabs(negotiated_.interval.fps() - config_.fps) > 0.005 * config_.fps)
      notes.push_back(fmt::format("asked {:.2f} fps: the driver granted {:.2f}", config_.fps, negotiated_.interval.fps()));
  }
  if (config_.width > 0 && (config_.width != negotiated_.width || config_.height != negotiated_.height))
    notes.push_back("asked " + std::to_string(config_.width) + "x" + std::to_string(config_.height) +
                    ": the driver gave " + std::to_string(negotiated_.width) + "x" +
                    std::to_string(negotiated_.height));
  if (!format_reason_.empty()) notes.push_back(format_reason_);
  if (!negotiated_.streaming) notes.push_back("read() I/O, no driver timestamps");
  for (std::size_t i = 0; i < notes.size(); ++i) s << (i ? "; " : " (") << notes[i];
  if (!notes.empty()) s << ")";
  negotiated_.summary = s.str();
}

void V4l2Camera::SetFrameInterval() {
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_.Ioctl(fd_, VIDIOC_G_PARM, &parm) < 0) return;  // the driver does not say
  negotiated_.interval_settable = parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME;
  negotiated_.interval = {parm.parm.capture.timeperframe.numerator,
                          parm.parm.capture.timeperframe.denominator};
  if (config_.fps <= 0 || !negotiated_.interval_settable) return;
  v4l2_streamparm want{};
  want.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  const double rounded = std::round(config_.fps);
  if (std::fabs(rounded - config_.fps) < 1e-9) {
    want.parm.capture.timeperframe = {1, static_cast<uint32_t>(rounded)};
  } else {
    want.parm.capture.timeperframe = {1000, static_cast<uint32_t>(std::lround(config_.fps * 1000))};
  }
  if (io_.Ioctl(fd_, VIDIOC_S_PARM, &want) < 0)
    throw std::runtime_error(config_.device + ": cannot set the frame interval: " +
                             ErrnoText(errno));
  // The driver writes back what it granted; read it again in case it does not.
  v4l2_streamparm granted{};
  granted.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_.Ioctl(fd_, VIDIOC_G_PARM, &granted) == 0 && granted.parm.capture.timeperframe.denominator)
    want = granted;
  negotiated_.interval = {want.parm.capture.timeperframe.numerator,
                          want.parm.capture.timeperframe.denominator};
}

void V4l2Camera::StartStreaming() {
  if (!negotiated_.streaming) {
    read_buffer_.resize(negotiated_.size_image);
    return;
  }
  v4l2_requestbuffers req{};
  req.count = static_cast<uint32_t>(config_.buffers);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (io_.Ioctl(fd_, VIDIOC_REQBUFS, &req) < 0)
    throw std::runtime_error(config_.device + ": cannot get mmap buffers: " + ErrnoText(errno));
  if (req.count < 2)
    throw std::runtime_error(config_.device + ": the driver granted only " +
                             std::to_string(req.count) + " buffer(s), at least 2 are needed");
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (io_.Ioctl(fd_, VIDIOC_QUERYBUF, &b) < 0)
      throw std::runtime_error(config_.device + ": VIDIOC_QUERYBUF failed: " + ErrnoText(errno));
    void* start = io_.Mmap(b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
    if (start == MAP_FAILED)
      throw std::runtime_error(config_.device + ": cannot mmap buffer " + std::to_string(i) +
                               ": " + ErrnoText(errno));
    buffers_.push_back({start, b.length});
  }
  negotiated_.buffers = static_cast<int>(buffers_.size());
  for (uint32_t i = 0; i < buffers_.size(); ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (io_.Ioctl(fd_, VIDIOC_QBUF, &b) < 0)
      throw std::runtime_error(config_.device + ": VIDIOC_QBUF failed: " + ErrnoText(errno));
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_.Ioctl(fd_, VIDIOC_STREAMON, &type) < 0)
    throw std::runtime_error(config_.device + ": cannot start streaming: " + ErrnoText(errno));
  streaming_on_ = true;
}

void V4l2Camera::Stop() {
  if (fd_ < 0) return;
  if (streaming_on_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    io_.Ioctl(fd_, VIDIOC_STREAMOFF, &type);  // fails harmlessly when the device is gone
    streaming_on_ = false;
  }
  for (auto& b : buffers_) io_.Munmap(b.start, b.length);
  buffers_.clear();
  if (negotiated_.streaming) {
    // Release the driver's buffers (count 0); ignored if the device is gone.
    v4l2_requestbuffers req{};
    req.count = 0;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    io_.Ioctl(fd_, VIDIOC_REQBUFS, &req);
  }
  io_.Close(fd_);
  fd_ = -1;
}

SourceInfo V4l2Camera::Info() const {
  SourceInfo info;
  info.description = negotiated_.summary;
  info.width = negotiated_.width;
  info.height = negotiated_.height;
  info.nominal_fps = negotiated_.interval.fps();
  info.frame_count = -1;
  return info;
}

void V4l2Camera::CountSequence(int64_t sequence) {
  if (last_sequence_ && sequence > *last_sequence_ + 1)
    dropped_ += sequence - *last_sequence_ - 1;
  last_sequence_ = sequence;
}

std::optional<Frame> V4l2Camera::ToFrame(const uint8_t* data, std::size_t size, int64_t utime,
                                         int64_t sequence) {
  Frame frame;
  frame.utime = utime;
  frame.sequence = sequence;
  if (negotiated_.fourcc == V4L2_PIX_FMT_YUYV) {
    const std::size_t needed =
        std::size_t(negotiated_.bytes_per_line) * std::size_t(negotiated_.height - 1) +
        std::size_t(negotiated_.width) * 2;
    if (size < needed) return std::nullopt;
    cv::Mat view(negotiated_.height, negotiated_.width, CV_8UC2, const_cast<uint8_t*>(data),
                 static_cast<std::size_t>(negotiated_.bytes_per_line));
    frame.image = view.clone();
    frame.format = PixelFormat::kYuyv;
  } else {
    if (size == 0) return std::nullopt;
    const cv::Mat encoded(1, static_cast<int>(size), CV_8UC1, const_cast<uint8_t*>(data));
    try {
      frame.image = cv::imdecode(encoded, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      return std::nullopt;
    }
    if (frame.image.empty()) return std::nullopt;
    frame.format = PixelFormat::kBgr24;
  }
  frame.owns_image = true;  // a copy or a decode of the driver's buffer, never written again
  return frame;
}

std::optional<Frame> V4l2Camera::Next() {
  if (fd_ < 0) return std::nullopt;
  if (failed_) throw std::runtime_error(config_.device + ": the camera has already failed");
  if (pending_error_) {
    const int err = pending_error_;
    pending_error_ = 0;
    Fail("VIDIOC_QBUF", err);
  }
  if (!negotiated_.streaming) return NextRead();
  int consecutive_errors = 0;
  // poll() may keep reporting readiness while DQBUF keeps saying EAGAIN (a driver in a bad
  // state): give up at the same timeout as for silence, instead of spinning.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(config_.timeout_ms);
  for (;;) {
    WaitReadable();
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (io_.Ioctl(fd_, VIDIOC_DQBUF, &b) < 0) {
      const int err = errno;
      if (err == EAGAIN) {  // woken with nothing ready: poll again
        ++eagain_;
        if (std::chrono::steady_clock::now() > deadline) {
          failed_ = true;
          throw std::runtime_error(fmt::format("{}: no frame for {:.1f} s, the driver only says EAGAIN (after {} frames)",
                                               config_.device, config_.timeout_ms / 1000.0, delivered_));
        }
        continue;
      }
      if (err == EIO && ++consecutive_errors <= config_.max_consecutive_errors) continue;
      Fail("VIDIOC_DQBUF", err);
    }
    if (b.index >= buffers_.size()) {
      failed_ = true;
      throw std::runtime_error(config_.device + ": the driver returned buffer " +
                               std::to_string(b.index) + " of " +
                               std::to_string(buffers_.size()));
    }
    int64_t utime = int64_t(b.timestamp.tv_sec) * 1000000 + int64_t(b.timestamp.tv_usec);
    if (utime == 0) {  // a driver without timestamps: stamp it on arrival
      utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::steady_clock::now().time_since_epoch())
                  .count();
    }
    const int64_t sequence = b.sequence;
    std::optional<Frame> frame;
    if (!(b.flags & V4L2_BUF_FLAG_ERROR)) {
      const std::size_t used = std::min<std::size_t>(b.bytesused, buffers_[b.index].length);
      frame = ToFrame(static_cast<const uint8_t*>(buffers_[b.index].start), used, utime, sequence);
    }
    // Give the buffer straight back; the frame was copied out of it.
    if (io_.Ioctl(fd_, VIDIOC_QBUF, &b) < 0) {
      if (!frame) Fail("VIDIOC_QBUF", errno);
      pending_error_ = errno;  // deliver this frame, fail on the next call
    }
    CountSequence(sequence);
    if (!frame) {
      ++error_frames_;
      ++dropped_;
      if (++consecutive_errors > config_.max_consecutive_errors) {
        failed_ = true;
        throw std::runtime_error(config_.device + ": " + std::to_string(consecutive_errors) +
                                 " bad frames in a row (after " + std::to_string(delivered_) +
                                 " frames)");
      }
      continue;
    }
    frame->index = delivered_++;
    return frame;
  }
}

// Waits until the device has a frame; a silent device for timeout_ms is an error (with the
// count of frames already delivered, which stay valid).
void V4l2Camera::WaitReadable() {
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    const int r = io_.Poll(&p, 1, config_.timeout_ms);
    if (r > 0) return;
    if (r < 0) {
      if (errno == EINTR) continue;
      Fail("poll", errno);
    }
    failed_ = true;
    throw std::runtime_error(
        fmt::format("{}: no frame for {:.1f} s (after {} frames)", config_.device, config_.timeout_ms / 1000.0, delivered_));
  }
}

std::optional<Frame> V4l2Camera::NextRead() {
  int consecutive_errors = 0;
  for (;;) {
    WaitReadable();
    const ssize_t n = io_.Read(fd_, read_buffer_.data(), read_buffer_.size());
    if (n < 0) {
      const int err = errno;
      if (err == EAGAIN || err == EINTR) {
        if (err == EAGAIN) ++eagain_;
        continue;
      }
      if (err == EIO && ++consecutive_errors <= config_.max_consecutive_errors) continue;
      Fail("read", err);
    }
    // read() I/O carries no driver timestamp: stamp it on arrival.
    const int64_t utime = std::chrono::duration_cast<std::chrono::microseconds>(
                              std::chrono::steady_clock::now().time_since_epoch())
                              .count();
    auto frame = ToFrame(read_buffer_.data(), static_cast<std::size_t>(n), utime, delivered_);
    if (!frame) {
      ++error_frames_;
      if (++consecutive_errors > config_.max_consecutive_errors) Fail("read", EIO);
      continue;
    }
    frame->index = delivered_++;
    return frame;
  }
}

}  // namespace bouncefit
