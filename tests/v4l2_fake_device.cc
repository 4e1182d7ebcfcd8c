#include "tests/v4l2_fake_device.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace bouncefit {
namespace {

constexpr off_t kOffsetStride = off_t(1) << 26;  // buffer i is mapped at i * 64 MiB
constexpr int kSquare = 24;

void CopyText(uint8_t* out, std::size_t size, const std::string& text) {
  std::memset(out, 0, size);
  std::memcpy(out, text.data(), std::min(size - 1, text.size()));
}

uint8_t Clamp(double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

// BGR to packed YUYV with BT.601 limited-range coefficients (what cv::COLOR_YUV2BGR_YUYV
// inverts).
void BgrToYuyv(const cv::Mat& bgr, uint8_t* out, std::size_t stride) {
  for (int y = 0; y < bgr.rows; ++y) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    uint8_t* o = out + std::size_t(y) * stride;
    for (int x = 0; x + 1 < bgr.cols; x += 2) {
      double yy[2], u = 0, v = 0;
      for (int k = 0; k < 2; ++k) {
        const double b = row[x + k][0], g = row[x + k][1], r = row[x + k][2];
        yy[k] = 16 + 0.257 * r + 0.504 * g + 0.098 * b;
        u += 128 - 0.148 * r - 0.291 * g + 0.439 * b;
        v += 128 + 0.439 * r - 0.368 * g - 0.071 * b;
      }
      o[2 * x + 0] = Clamp(yy[0]);
      o[2 * x + 1] = Clamp(u / 2);
      o[2 * x + 2] = Clamp(yy[1]);
      o[2 * x + 3] = Clamp(v / 2);
    }
  }
}

}  // namespace

FakeV4l2Device::FakeV4l2Device(FakeV4l2Script script)
    : script_(std::move(script)), events_(script_.events.begin(), script_.events.end()) {
  if (!script_.formats.empty() && !script_.formats[0].sizes.empty()) {
    const auto& f = script_.formats[0];
    fourcc_ = f.fourcc;
    width_ = f.sizes[0].width;
    height_ = f.sizes[0].height;
    if (!f.sizes[0].intervals.empty()) interval_ = f.sizes[0].intervals.back();
  }
}

std::vector<FakeV4l2Format> FakeV4l2Device::TypicalFormats() {
  return {
      {V4L2_PIX_FMT_YUYV, "YUYV 4:2:2",
       {{640, 480, {{1, 120}, {1, 60}, {1, 30}}}, {1280, 720, {{1, 30}, {1, 15}}}}},
      {V4L2_PIX_FMT_MJPEG, "Motion-JPEG",
       {{640, 480, {{1, 120}, {1, 60}, {1, 30}}}, {1280, 720, {{1, 120}, {1, 60}, {1, 30}}}}},
  };
}

FakeV4l2Script FakeV4l2Device::TypicalScript(std::vector<FakeV4l2Event> events) {
  FakeV4l2Script s;
  s.formats = TypicalFormats();
  s.events = std::move(events);
  return s;
}

V4l2CameraConfig FakeV4l2Device::CameraConfig(int width, int height, double fps) {
  V4l2CameraConfig c;
  c.device = "/dev/video0";
  c.width = width;
  c.height = height;
  c.fps = fps;
  c.timeout_ms = 200;
  return c;
}

std::vector<FakeV4l2Event> FakeV4l2Device::Frames(int64_t first_sequence, int count, double fps,
                                                  const std::vector<int64_t>& skip,
                                                  int64_t t0_us) {
  std::vector<FakeV4l2Event> events;
  for (int64_t s = first_sequence; static_cast<int>(events.size()) < count; ++s) {
    if (std::find(skip.begin(), skip.end(), s) != skip.end()) continue;
    events.push_back({FakeV4l2Event::kFrame, s,
                      t0_us + std::llround(double(s - first_sequence) * 1e6 / fps)});
  }
  return events;
}

cv::Point FakeV4l2Device::SquareCorner(int width, int height, int64_t sequence) {
  const int span_x = std::max(2, (width - kSquare) / 8) & ~1;  // even: YUYV pairs pixels
  const int span_y = std::max(1, (height - kSquare) / 8);
  return {static_cast<int>(sequence % 7) * span_x, static_cast<int>((sequence / 7) % 7) * span_y};
}

cv::Mat FakeV4l2Device::Picture(int width, int height, int64_t sequence) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(90, 90, 90));
  const cv::Point c = SquareCorner(width, height, sequence);
  cv::rectangle(img, cv::Rect(c.x, c.y, kSquare, kSquare), cv::Scalar(30, 30, 230), cv::FILLED);
  return img;
}

const FakeV4l2Format* FakeV4l2Device::FindFormat(uint32_t fourcc) const {
  for (const auto& f : script_.formats)
    if (f.fourcc == fourcc) return &f;
  return nullptr;
}

const FakeV4l2Size* FakeV4l2Device::FindSize(const FakeV4l2Format& f, int w, int h) const {
  const FakeV4l2Size* best = nullptr;
  long best_d = 0;
  for (const auto& s : f.sizes) {
    const long d = std::labs(long(s.width) - w) + std::labs(long(s.height) - h);
    if (!best || d < best_d) {
      best = &s;
      best_d = d;
    }
  }
  return best;
}

const FakeV4l2Size* FakeV4l2Device::CurrentSize() const {
  const auto* f = FindFormat(fourcc_);
  return f ? FindSize(*f, width_, height_) : nullptr;
}

int FakeV4l2Device::Fail(int err) {
  errno = err;
  return -1;
}

int FakeV4l2Device::Misuse(const std::string& what, int err) {
  if (misuse_.empty()) misuse_ = what;
  return Fail(err);
}

std::size_t FakeV4l2Device::FrameBytes() const {
  return std::size_t(width_) * std::size_t(height_) * 2;
}

int FakeV4l2Device::Open(const std::string& path, int flags) {
  if (path != script_.path) return Fail(ENOENT);
  if (gone_) return Fail(ENODEV);
  const int fd = next_fd_++;
  open_[fd] = (flags & O_NONBLOCK) != 0;
  return fd;
}

int FakeV4l2Device::Close(int fd) {
  if (!open_.erase(fd)) return Misuse("close of a descriptor that is not open", EBADF);
  if (open_.empty()) {  // the last close releases everything, as the kernel does
    streaming_ = false;
    queue_.clear();
  }
  return 0;
}

int FakeV4l2Device::Ioctl(int fd, unsigned long request, void* arg) {
  if (!open_.count(fd)) return Misuse("ioctl on a descriptor that is not open", EBADF);
  if (gone_) return Fail(ENODEV);
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      std::memset(cap, 0, sizeof *cap);
      CopyText(cap->driver, sizeof cap->driver, script_.driver);
      CopyText(cap->card, sizeof cap->card, script_.card);
      CopyText(cap->bus_info, sizeof cap->bus_info, script_.bus_info);
      cap->version = 0x060100;
      cap->device_caps = V4L2_CAP_VIDEO_CAPTURE |
                         (script_.streaming ? V4L2_CAP_STREAMING : V4L2_CAP_READWRITE);
      cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto* d = static_cast<v4l2_fmtdesc*>(arg);
      if (d->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || d->index >= script_.formats.size())
        return Fail(EINVAL);
      const auto& f = script_.formats[d->index];
      d->pixelformat = f.fourcc;
      d->flags = f.fourcc == V4L2_PIX_FMT_YUYV ? 0 : V4L2_FMT_FLAG_COMPRESSED;
      CopyText(d->description, sizeof d->description, f.description);
      return 0;
    }
    case VIDIOC_ENUM_FRAMESIZES: {
      auto* s = static_cast<v4l2_frmsizeenum*>(arg);
      const auto* f = FindFormat(s->pixel_format);
      if (!f || s->index >= f->sizes.size()) return Fail(EINVAL);
      s->type = V4L2_FRMSIZE_TYPE_DISCRETE;
      s->discrete.width = static_cast<uint32_t>(f->sizes[s->index].width);
      s->discrete.height = static_cast<uint32_t>(f->sizes[s->index].height);
      return 0;
    }
    case VIDIOC_ENUM_FRAMEINTERVALS: {
      auto* e = static_cast<v4l2_frmivalenum*>(arg);
      const auto* f = FindFormat(e->pixel_format);
      if (!f) return Fail(EINVAL);
      const FakeV4l2Size* size = nullptr;
      for (const auto& s : f->sizes)
        if (s.width == int(e->width) && s.height == int(e->height)) size = &s;
      if (!size || e->index >= size->intervals.size()) return Fail(EINVAL);
      e->type = V4L2_FRMIVAL_TYPE_DISCRETE;
      e->discrete.numerator = size->intervals[e->index].numerator;
      e->discrete.denominator = size->intervals[e->index].denominator;
      return 0;
    }
    case VIDIOC_G_FMT:
    case VIDIOC_S_FMT: {
      auto* fmt = static_cast<v4l2_format*>(arg);
      if (fmt->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request == VIDIOC_S_FMT) {
        if (streaming_ || !buffers_.empty()) return Fail(EBUSY);
        const auto* f = FindFormat(fmt->fmt.pix.pixelformat);
        if (!f) f = &script_.formats.at(0);  // drivers fall back instead of failing
        const auto* s = FindSize(*f, int(fmt->fmt.pix.width), int(fmt->fmt.pix.height));
        fourcc_ = f->fourcc;
        width_ = s->width;
        height_ = s->height;
        const bool listed = std::any_of(s->intervals.begin(), s->intervals.end(), [&](auto i) {
          return i.numerator == interval_.numerator && i.denominator == interval_.denominator;
        });
        if (!listed && !s->intervals.empty()) interval_ = s->intervals.back();
      }
      std::memset(&fmt->fmt.pix, 0, sizeof fmt->fmt.pix);
      fmt->fmt.pix.width = static_cast<uint32_t>(width_);
      fmt->fmt.pix.height = static_cast<uint32_t>(height_);
      fmt->fmt.pix.pixelformat = fourcc_;
      fmt->fmt.pix.field = V4L2_FIELD_NONE;
      fmt->fmt.pix.bytesperline = fourcc_ == V4L2_PIX_FMT_YUYV ? uint32_t(2 * width_) : 0;
      fmt->fmt.pix.sizeimage = static_cast<uint32_t>(FrameBytes());
      fmt->fmt.pix.colorspace = V4L2_COLORSPACE_SRGB;
      return 0;
    }
    case VIDIOC_G_PARM:
    case VIDIOC_S_PARM: {
      auto* p = static_cast<v4l2_streamparm*>(arg);
      if (p->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request == VIDIOC_S_PARM && script_.timeperframe) {
        const auto asked = p->parm.capture.timeperframe;
        const double fps = asked.numerator ? double(asked.denominator) / asked.numerator : 0;
        const auto* s = CurrentSize();
        if (script_.grant_only) {
          interval_ = *script_.grant_only;
        } else if (s && fps > 0) {
          double best = 1e18;
          for (const auto& i : s->intervals) {
            const double d = std::fabs(i.fps() - fps);
            if (d < best) {
              best = d;
              interval_ = i;
            }
          }
        }
      }
      std::memset(&p->parm, 0, sizeof p->parm);
      p->parm.capture.capability = script_.timeperframe ? V4L2_CAP_TIMEPERFRAME : 0;
      p->parm.capture.timeperframe = {interval_.numerator, interval_.denominator};
      p->parm.capture.readbuffers = 2;
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* r = static_cast<v4l2_requestbuffers*>(arg);
      if (!script_.streaming) return Fail(EINVAL);
      if (r->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || r->memory != V4L2_MEMORY_MMAP)
        return Fail(EINVAL);
      if (streaming_) return Fail(EBUSY);
      if (r->count > 0 && !buffers_.empty()) return Misuse("REQBUFS twice without freeing", EBUSY);
      if (r->count == 0) {
        if (mapped_ > 0) return Misuse("REQBUFS 0 with buffers still mapped", EBUSY);
        buffers_.clear();
        queue_.clear();
        return 0;
      }
      requested_buffers_ = static_cast<int>(r->count);
      r->count = std::min<uint32_t>(r->count, static_cast<uint32_t>(script_.max_buffers));
      buffers_.assign(r->count, Buffer{});
      for (auto& b : buffers_) b.memory.assign(FrameBytes(), 0);
      return 0;
    }
    case VIDIOC_QUERYBUF:
    case VIDIOC_QBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || b->memory != V4L2_MEMORY_MMAP ||
          b->index >= buffers_.size())
        return Misuse("bad buffer in QUERYBUF/QBUF", EINVAL);
      auto& buf = buffers_[b->index];
      if (request == VIDIOC_QBUF) {
        if (buf.queued) return Misuse("buffer queued twice", EINVAL);
        buf.queued = true;
        queue_.push_back(b->index);
      }
      b->length = static_cast<uint32_t>(buf.memory.size());
      b->m.offset = static_cast<uint32_t>(b->index * kOffsetStride);
      b->flags = buf.queued ? V4L2_BUF_FLAG_QUEUED : 0;
      return 0;
    }
    case VIDIOC_STREAMON:
      if (buffers_.empty() || queue_.empty()) return Misuse("STREAMON with no buffer queued", EINVAL);
      streaming_ = true;
      return 0;
    case VIDIOC_STREAMOFF:
      ++streamoff_calls_;
      streaming_ = false;
      queue_.clear();
      for (auto& b : buffers_) b.queued = false;
      return 0;
    case VIDIOC_DQBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (!streaming_) return Misuse("DQBUF while not streaming", EINVAL);
      if (events_.empty()) return Fail(EAGAIN);
      const FakeV4l2Event e = events_.front();
      if (e.kind == FakeV4l2Event::kEagain) {
        events_.pop_front();
        return Fail(EAGAIN);
      }
      if (e.kind == FakeV4l2Event::kEio) {
        events_.pop_front();
        return Fail(EIO);
      }
      if (e.kind == FakeV4l2Event::kEnodev) {
        gone_ = true;
        return Fail(ENODEV);
      }
      if (queue_.empty()) return Misuse("DQBUF with no buffer queued (buffers not requeued?)", EINVAL);
      events_.pop_front();
      const uint32_t index = queue_.front();
      queue_.pop_front();
      auto& buf = buffers_[index];
      buf.queued = false;
      std::memset(b, 0, sizeof *b);
      b->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b->memory = V4L2_MEMORY_MMAP;
      b->index = index;
      b->bytesused = static_cast<uint32_t>(Fill(buf.memory.data(), buf.memory.size(), e));
      b->length = static_cast<uint32_t>(buf.memory.size());
      b->m.offset = static_cast<uint32_t>(index * kOffsetStride);
      b->sequence = static_cast<uint32_t>(e.sequence);
      b->timestamp.tv_sec = e.utime / 1000000;
      b->timestamp.tv_usec = e.utime % 1000000;
      b->field = V4L2_FIELD_NONE;
      b->flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
      if (e.kind == FakeV4l2Event::kErrorFrame) b->flags |= V4L2_BUF_FLAG_ERROR;
      ++dequeued_;
      return 0;
    }
    default:
      return Fail(ENOTTY);
  }
}

std::size_t FakeV4l2Device::Fill(uint8_t* out, std::size_t capacity, const FakeV4l2Event& e) {
  if (e.kind == FakeV4l2Event::kCorruptFrame) {
    const std::size_t n = std::min<std::size_t>(capacity, 1000);
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<uint8_t>(i * 37 + 11);
    return fourcc_ == V4L2_PIX_FMT_YUYV ? n / 4 : n;  // too short for YUYV, not a JPEG
  }
  const cv::Mat picture = Picture(width_, height_, e.sequence);
  if (fourcc_ == V4L2_PIX_FMT_YUYV) {
    BgrToYuyv(picture, out, std::size_t(2 * width_));
    return FrameBytes();
  }
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", picture, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
  const std::size_t n = std::min(capacity, jpeg.size());
  std::memcpy(out, jpeg.data(), n);
  return n;
}

void* FakeV4l2Device::Mmap(std::size_t length, int prot, int flags, int fd, off_t offset) {
  if (!open_.count(fd)) {
    errno = EBADF;
    return MAP_FAILED;
  }
  const auto index = static_cast<std::size_t>(offset / kOffsetStride);
  if (gone_ || offset % kOffsetStride != 0 || index >= buffers_.size() ||
      length != buffers_[index].memory.size() || !(flags & MAP_SHARED)) {
    errno = gone_ ? ENODEV : EINVAL;
    return MAP_FAILED;
  }
  if (buffers_[index].mapped) {
    Misuse("buffer mapped twice", EINVAL);
    return MAP_FAILED;
  }
  buffers_[index].mapped = true;
  ++mapped_;
  return buffers_[index].memory.data();
}

int FakeV4l2Device::Munmap(void* addr, std::size_t length) {
  for (auto& b : buffers_) {
    if (b.mapped && b.memory.data() == addr && b.memory.size() == length) {
      b.mapped = false;
      --mapped_;
      return 0;
    }
  }
  return Misuse("munmap of memory that is not mapped", EINVAL);
}

int FakeV4l2Device::Poll(pollfd* fds, nfds_t count, int timeout_ms) {
  int ready = 0;
  for (nfds_t i = 0; i < count; ++i) {
    fds[i].revents = 0;
    if (!open_.count(fds[i].fd)) {
      fds[i].revents = POLLNVAL;
    } else if (gone_) {
      fds[i].revents = POLLERR | POLLHUP;
    } else if (events_.empty() && script_.stuck_after_events) {
      fds[i].revents = POLLIN;
    } else if (!events_.empty()) {
      fds[i].revents = events_.front().kind == FakeV4l2Event::kEnodev ? (POLLERR | POLLHUP)
                                                                      : POLLIN;
    }
    if (fds[i].revents) ++ready;
  }
  return ready;  // 0: the script is over, as if timeout_ms passed with no frame
}

ssize_t FakeV4l2Device::Read(int fd, void* buffer, std::size_t size) {
  if (!open_.count(fd)) return Misuse("read on a descriptor that is not open", EBADF);
  if (gone_) return Fail(ENODEV);
  if (events_.empty()) return Fail(EAGAIN);
  const FakeV4l2Event e = events_.front();
  events_.pop_front();
  switch (e.kind) {
    case FakeV4l2Event::kEagain: return Fail(EAGAIN);
    case FakeV4l2Event::kEio: return Fail(EIO);
    case FakeV4l2Event::kEnodev: gone_ = true; return Fail(ENODEV);
    default: break;
  }
  std::vector<uint8_t> tmp(FrameBytes());
  const std::size_t n = std::min(size, Fill(tmp.data(), tmp.size(), e));
  std::memcpy(buffer, tmp.data(), n);
  ++dequeued_;
  return static_cast<ssize_t>(n);
}

}  // namespace bouncefit
