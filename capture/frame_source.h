#pragma once
// A source of frames: a V4L2 camera or a video file replayed as a fake camera. The nodes
// behind it cannot tell the two apart.
#include <optional>
#include <string>

#include "capture/frame.h"

namespace bouncefit {

struct SourceInfo {
  std::string description;  // "file clip.avi (MJPG 640x480)", "/dev/video0 YUYV 640x480"
  int width = 0;
  int height = 0;
  double nominal_fps = 0;   // frames per second the source claims
  int64_t frame_count = -1; // -1 when unknown (cameras)
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual SourceInfo Info() const = 0;
  // The next frame, or nullopt at the end of the stream. Throws std::runtime_error with a
  // one-line reason on a failure (device gone, corrupt file); frames already returned stay
  // valid.
  virtual std::optional<Frame> Next() = 0;
  // Frames the source knows it lost (sequence gaps), so far.
  virtual int64_t dropped_frames() const { return 0; }
};

}  // namespace bouncefit
