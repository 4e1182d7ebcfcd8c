#pragma once
// A V4L2 camera as a FrameSource, through the kernel API (linux/videodev2.h): format, size
// and frame-interval negotiation, mmap streaming with several buffers, the driver's capture
// timestamps and sequence numbers (gaps counted as dropped frames).
//
// Every system call goes through V4l2Io, so tests drive this very code with a scripted fake
// device (tests/v4l2_fake_device.h).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "capture/v4l2_io.h"

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
};

// What the driver granted.
struct V4l2Negotiated {
  uint32_t fourcc = 0;
  int width = 0;
  int height = 0;
  int bytes_per_line = 0;
  uint32_t size_image = 0;
  V4l2Interval interval;
  bool interval_settable = false;  // driver supports V4L2_CAP_TIMEPERFRAME
  int buffers = 0;
  bool streaming = true;           // false: read() I/O
  // One line: "/dev/video0 (UVC Camera): YUYV 640x480 at 60.00 fps (asked 120 fps: the
  // driver granted 60.00)".
  std::string summary;
};

std::string FourccToString(uint32_t fourcc);

// Capture devices (nodes that can capture video), in device-number order.
std::vector<V4l2DeviceInfo> ListV4l2Devices(V4l2Io& io = SystemV4l2Io());
// Formats, frame sizes and frame intervals a device offers. Throws std::runtime_error.
std::vector<V4l2FormatInfo> ListV4l2Formats(const std::string& device,
                                            V4l2Io& io = SystemV4l2Io());

class V4l2Camera final : public FrameSource {
 public:
  // Opens, negotiates and starts streaming. Throws std::runtime_error with a one-line reason.
  explicit V4l2Camera(V4l2CameraConfig config, V4l2Io& io = SystemV4l2Io());
  ~V4l2Camera() override;  // Stop()
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  SourceInfo Info() const override;
  // The next frame (copied out of the driver's buffer, which goes straight back to the
  // driver). Throws std::runtime_error when the device fails or vanishes; frames already
  // returned stay valid and the counters stay readable.
  std::optional<Frame> Next() override;
  int64_t dropped_frames() const override { return dropped_; }

  const V4l2Negotiated& negotiated() const { return negotiated_; }
  int64_t eagain_count() const { return eagain_; }
  int64_t error_frames() const { return error_frames_; }  // flagged or undecodable, skipped

  // Stops streaming, unmaps the buffers and closes the device. Never throws; idempotent.
  void Stop();

 private:
  struct Buffer {
    void* start = nullptr;
    std::size_t length = 0;
  };

  void Negotiate();
  uint32_t ChooseFormat(const std::vector<V4l2FormatInfo>& formats);
  void SetFrameInterval();
  void StartStreaming();
  std::optional<Frame> ToFrame(const uint8_t* data, std::size_t size, int64_t utime,
                               int64_t sequence);
  std::optional<Frame> NextRead();
  void WaitReadable();
  [[noreturn]] void Fail(const std::string& what, int err);
  void CountSequence(int64_t sequence);

  V4l2CameraConfig config_;
  V4l2Io& io_;
  int fd_ = -1;
  std::string card_;
  V4l2Negotiated negotiated_;
  std::vector<Buffer> buffers_;
  std::vector<uint8_t> read_buffer_;
  bool streaming_on_ = false;
  bool failed_ = false;
  int64_t delivered_ = 0;
  int64_t dropped_ = 0;
  int64_t eagain_ = 0;
  int64_t error_frames_ = 0;
  std::optional<int64_t> last_sequence_;
  std::string format_reason_;
  int pending_error_ = 0;
};

}  // namespace bouncefit
