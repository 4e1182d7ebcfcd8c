#pragma once
// A V4L2 camera as a FrameSource, through the kernel API (linux/videodev2.h): it opens the
// device, negotiates through capture/v4l2_negotiation.h, then streams: mmap buffers (read()
// I/O where the driver cannot stream), the driver's capture timestamps and sequence numbers
// (gaps counted as dropped frames), each buffer copied or decoded into a Frame.
//
// Every system call goes through V4l2Io, so tests drive this very code with a scripted fake
// device (tests/v4l2_fake_device.h).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "capture/v4l2_camera_config.h"
#include "capture/v4l2_io.h"
#include "capture/v4l2_negotiation.h"

namespace bouncefit {

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
  int pending_error_ = 0;
};

}  // namespace bouncefit
