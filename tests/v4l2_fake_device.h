#pragma once
// A scripted V4L2 device behind the V4l2Io seam, for driving the real V4l2Camera code in
// tests: it answers the ioctls a UVC driver answers (QUERYCAP, ENUM_FMT/FRAMESIZES/
// FRAMEINTERVALS, G/S_FMT, G/S_PARM, REQBUFS, QUERYBUF, QBUF, DQBUF, STREAMON/OFF), maps its
// buffers, and plays a script of what successive dequeues see: frames with chosen sequence
// numbers and timestamps, EAGAIN, EIO, flagged or corrupt frames, ENODEV (the camera
// unplugged). It also records what the camera did, so tests can check the clean-up.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "capture/v4l2_camera.h"
#include "capture/v4l2_io.h"

namespace bouncefit {

struct FakeV4l2Size {
  int width = 0;
  int height = 0;
  std::vector<V4l2Interval> intervals;  // fastest first, as UVC cameras list them
};

struct FakeV4l2Format {
  uint32_t fourcc = 0;
  std::string description;
  std::vector<FakeV4l2Size> sizes;
};

struct FakeV4l2Event {
  enum Kind {
    kFrame,         // a good frame
    kErrorFrame,    // a frame flagged V4L2_BUF_FLAG_ERROR
    kCorruptFrame,  // a frame whose bytes cannot be decoded
    kEagain,        // DQBUF fails with EAGAIN once (a spurious wake-up)
    kEio,           // DQBUF fails with EIO once
    kEnodev,        // the device is gone: every later call fails with ENODEV
  };
  Kind kind = kFrame;
  int64_t sequence = 0;
  int64_t utime = 0;
};

struct FakeV4l2Script {
  std::string path = "/dev/video0";
  std::string card = "Fake UVC Camera";
  std::string driver = "uvcvideo";
  std::string bus_info = "usb-fake-1";
  bool streaming = true;        // V4L2_CAP_STREAMING (else read() I/O only)
  bool timeperframe = true;     // V4L2_CAP_TIMEPERFRAME: S_PARM is honoured
  std::vector<FakeV4l2Format> formats;
  std::optional<V4l2Interval> grant_only;  // S_PARM grants this whatever is asked
  int max_buffers = 8;
  std::vector<FakeV4l2Event> events;       // after the last one, poll times out...
  bool stuck_after_events = false;         // ...or says ready while DQBUF says EAGAIN forever
};

class FakeV4l2Device final : public V4l2Io {
 public:
  explicit FakeV4l2Device(FakeV4l2Script script);

  // A typical UVC webcam: YUYV 640x480 up to 120 fps and 1280x720 up to 30 fps, MJPEG at
  // both sizes up to 120 fps.
  static std::vector<FakeV4l2Format> TypicalFormats();
  // That webcam at /dev/video0 playing these events.
  static FakeV4l2Script TypicalScript(std::vector<FakeV4l2Event> events);
  // A camera config for it: w x h at fps, a 200 ms timeout so silence fails fast.
  static V4l2CameraConfig CameraConfig(int width = 640, int height = 480, double fps = 120);
  // count good frames from sequence first_sequence at fps, leaving out the listed sequence
  // numbers (frames the "driver" dropped); timestamps start at t0_us.
  static std::vector<FakeV4l2Event> Frames(int64_t first_sequence, int count, double fps,
                                           const std::vector<int64_t>& skip = {},
                                           int64_t t0_us = 1000000);
  // The picture the device puts in the frame with this sequence number: a grey background
  // with a bright red square whose position encodes the sequence number.
  static cv::Mat Picture(int width, int height, int64_t sequence);
  static cv::Point SquareCorner(int width, int height, int64_t sequence);

  // V4l2Io
  int Open(const std::string& path, int flags) override;
  int Close(int fd) override;
  int Ioctl(int fd, unsigned long request, void* arg) override;
  void* Mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override;
  int Munmap(void* addr, std::size_t length) override;
  int Poll(pollfd* fds, nfds_t count, int timeout_ms) override;
  ssize_t Read(int fd, void* buffer, std::size_t size) override;
  std::vector<std::string> DevicePaths() override { return {script_.path}; }

  // What the camera did.
  int open_fds() const { return static_cast<int>(open_.size()); }
  int mapped() const { return mapped_; }
  int requested_buffers() const { return requested_buffers_; }
  int granted_buffers() const { return static_cast<int>(buffers_.size()); }
  bool streaming() const { return streaming_; }
  int streamoff_calls() const { return streamoff_calls_; }
  int dequeued() const { return dequeued_; }
  int events_left() const { return static_cast<int>(events_.size()); }
  uint32_t fourcc() const { return fourcc_; }
  int width() const { return width_; }
  int height() const { return height_; }
  V4l2Interval interval() const { return interval_; }
  // Set when the camera misused the API (dequeued with nothing queued, queued twice, ...).
  const std::string& misuse() const { return misuse_; }

 private:
  struct Buffer {
    std::vector<uint8_t> memory;
    bool queued = false;
    bool mapped = false;
  };
  const FakeV4l2Format* FindFormat(uint32_t fourcc) const;
  const FakeV4l2Size* FindSize(const FakeV4l2Format& f, int w, int h) const;
  const FakeV4l2Size* CurrentSize() const;
  int Fail(int err);
  int Misuse(const std::string& what, int err);
  std::size_t FrameBytes() const;
  std::size_t Fill(uint8_t* out, std::size_t capacity, const FakeV4l2Event& e);

  FakeV4l2Script script_;
  std::deque<FakeV4l2Event> events_;
  std::map<int, bool> open_;
  int next_fd_ = 3;
  bool gone_ = false;
  uint32_t fourcc_ = 0;
  int width_ = 0;
  int height_ = 0;
  V4l2Interval interval_;
  std::vector<Buffer> buffers_;
  std::deque<uint32_t> queue_;
  bool streaming_ = false;
  int mapped_ = 0;
  int requested_buffers_ = 0;
  int streamoff_calls_ = 0;
  int dequeued_ = 0;
  std::string misuse_;
};

}  // namespace bouncefit
