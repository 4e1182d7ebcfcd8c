#include "capture/v4l2_camera.h"

#include <fmt/format.h>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <stdexcept>

namespace bouncefit {

V4l2Camera::V4l2Camera(V4l2CameraConfig config, V4l2Io& io)
    : config_(std::move(config)), io_(io) {
  config_.Validate();
  fd_ = io_.Open(config_.device, O_RDWR | O_NONBLOCK);
  if (fd_ < 0)
    throw std::runtime_error("cannot open " + config_.device + ": " + V4l2ErrnoText(errno));
  try {
    NegotiateV4l2Format(io_, fd_, config_, &negotiated_);
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
  throw std::runtime_error(config_.device + ": " + what + ": " + V4l2ErrnoText(err) + after);
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
    throw std::runtime_error(config_.device + ": cannot get mmap buffers: " + V4l2ErrnoText(errno));
  if (req.count < 2)
    throw std::runtime_error(config_.device + ": the driver granted only " +
                             std::to_string(req.count) + " buffer(s), at least 2 are needed");
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (io_.Ioctl(fd_, VIDIOC_QUERYBUF, &b) < 0)
      throw std::runtime_error(config_.device + ": VIDIOC_QUERYBUF failed: " + V4l2ErrnoText(errno));
    void* start = io_.Mmap(b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
    if (start == MAP_FAILED)
      throw std::runtime_error(config_.device + ": cannot mmap buffer " + std::to_string(i) +
                               ": " + V4l2ErrnoText(errno));
    buffers_.push_back({start, b.length});
  }
  negotiated_.buffers = static_cast<int>(buffers_.size());
  for (uint32_t i = 0; i < buffers_.size(); ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (io_.Ioctl(fd_, VIDIOC_QBUF, &b) < 0)
      throw std::runtime_error(config_.device + ": VIDIOC_QBUF failed: " + V4l2ErrnoText(errno));
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_.Ioctl(fd_, VIDIOC_STREAMON, &type) < 0)
    throw std::runtime_error(config_.device + ": cannot start streaming: " + V4l2ErrnoText(errno));
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