#pragma once
// A video file (.avi, .mp4, .mov, ...) as a fake camera, through OpenCV's FFmpeg backend.
// Frame times come from the container (CAP_PROP_POS_MSEC: the frame's presentation time),
// not from the nominal frame rate, so variable-frame-rate clips keep their true timing.
// A recording made by `capture --record` (capture/frame_recorder.h) carries the camera's
// own times and sequence numbers in FILE.times.csv: they are used when present.
// A file stored rotated (a phone's rotation tag) is turned upright: frames come out as a
// player shows them.
#include <opencv2/videoio.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "replay/repeated_frames.h"

namespace bouncefit {

struct VideoFileSourceConfig {
  std::string path;
  bool loop = false;  // start again at the end; times keep increasing across loops
  // Skip pictures the file repeats (replay/repeated_frames.h): 30 fps content on a 60 fps
  // timeline gives its 30 pictures a second, each at the time it was first shown. Not for a
  // recording with its camera's times file (each of its frames was captured).
  bool skip_repeats = true;
};

class VideoFileSource final : public FrameSource {
 public:
  // Opens the file and decodes its first frame. Throws std::runtime_error with a one-line
  // reason when the file is missing, unreadable or holds no decodable video.
  explicit VideoFileSource(VideoFileSourceConfig config);

  SourceInfo Info() const override { return info_; }
  // Frames in order; utime = container time of the frame since the first one (plus the
  // length of the previous passes when looping); index = the picture's number in the file
  // (gaps where repeats were skipped). nullopt at the end.
  std::optional<Frame> Next() override;

  int loops_done() const { return loops_; }
  // After the end: the last pass gave clearly fewer frames than the container announces
  // (a truncated or damaged file). Its frames were all delivered.
  bool ended_short() const { return ended_short_; }
  // Frames whose container time did not increase and was replaced by previous + one
  // nominal interval.
  int64_t repaired_times() const { return repaired_; }
  // Frames that could not be decoded (damaged data) and were skipped, the stream going on
  // after them: their time is a gap between the frames delivered.
  int64_t undecodable_frames() const { return undecodable_; }
  int64_t dropped_frames() const override { return dropped_; }
  // Pictures skipped as repeats of the one before (not delivered, not dropped).
  int64_t repeated_frames() const { return repeats_.repeats(); }
  bool uses_times_file() const { return !recorded_.empty(); }
  // Clockwise turn applied to every decoded frame to show it upright: 0, 90, 180 or 270 deg.
  int rotation_deg() const { return rotation_deg_; }

 private:
  void Open();
  void LoadTimes();
  std::optional<Frame> Decode();

  VideoFileSourceConfig config_;
  cv::VideoCapture capture_;
  SourceInfo info_;
  std::optional<Frame> pending_;  // decoded ahead (the first frame, read at open)
  int64_t delivered_ = 0;
  int64_t pass_offset_us_ = 0;    // added to container times in the current pass
  int64_t pass_first_us_ = -1;    // container time of the first frame of this pass
  int64_t last_utime_ = -1;
  int64_t last_step_us_ = 0;     // last interval between good container times
  int64_t pass_frames_ = 0;
  int loops_ = 0;
  int64_t dropped_ = 0;
  bool ended_short_ = false;
  struct Recorded {
    int64_t utime;
    int64_t sequence;
  };
  std::vector<Recorded> recorded_;  // from FILE.times.csv, one per frame
  int64_t repaired_ = 0;
  int64_t undecodable_ = 0, pass_undecodable_ = 0;
  int rotation_deg_ = 0;
  RepeatedFrameFilter repeats_;
  int64_t decoded_ = 0;  // pictures decoded over all passes, repeats included
};

}  // namespace bouncefit
