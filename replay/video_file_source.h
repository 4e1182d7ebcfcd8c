#pragma once
// A video file (.avi, .mp4, .mov, ...) as a fake camera, through FFmpeg's libraries
// (replay/av_video_reader.h). Frame times come from the container (each picture's
// presentation time), not from the nominal frame rate, so variable-frame-rate clips keep
// their true timing.
// A recording made by `capture --record` (capture/frame_recorder.h) carries the camera's
// own times and sequence numbers in FILE.times.csv: they are used when present.
// A file stored rotated (a phone's rotation tag) is turned upright: frames come out as a
// player shows them.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "capture/frame_source.h"
#include "replay/av_video_reader.h"
#include "replay/repeated_frames.h"

namespace bouncefit {

struct VideoFileSourceConfig {
  std::string path;
  bool loop = false;  // start again at the end; times keep increasing across loops
  // Skip pictures the file repeats (replay/repeated_frames.h): 30 fps content on a 60 fps
  // timeline gives its 30 pictures a second, each at the time it was first shown. Not for a
  // recording with its camera's times file (each of its frames was captured).
  bool skip_repeats = true;
  // Decode the next frames on a thread of its own while the caller works on this one (up to
  // this many frames ahead; 0: decode in Next()).
  int read_ahead = 0;
  // The decoder's threads, 0 for one per core (FFmpeg's choice).
  int decoder_threads = 0;
};

// How `run` reads a file: the next frames decoded on a thread of its own while the tracker
// works on this one, the decoder with its own threads (one for it alone measured slower on
// 6 of the 8 shared clips: docs/PERFORMANCE.md).
VideoFileSourceConfig ReadAheadConfig(std::string path);

class VideoFileSource final : public FrameSource {
 public:
  // Opens the file and decodes its first frame. Throws std::runtime_error with a one-line
  // reason when the file is missing, unreadable or holds no decodable video.
  explicit VideoFileSource(VideoFileSourceConfig config);
  ~VideoFileSource() override;

  SourceInfo Info() const override { return info_; }
  // Frames in order; utime = container time of the frame since the first one (plus the
  // length of the previous passes when looping); index = the picture's number in the file
  // (gaps where repeats were skipped). nullopt at the end.
  std::optional<Frame> Next() override;

  // The counts below are as of the last frame Next() returned (reading ahead, the decoder
  // thread's own run ahead of them).
  int loops_done() const { return shown_.loops; }
  // After the end: the last pass gave clearly fewer frames than the container announces
  // (a truncated or damaged file). Its frames were all delivered.
  bool ended_short() const { return shown_.ended_short; }
  // Frames whose container time did not increase and was replaced by previous + one
  // nominal interval.
  int64_t repaired_times() const { return shown_.repaired; }
  // Frames that could not be decoded (damaged data) and were skipped, the stream going on
  // after them: their time is a gap between the frames delivered.
  int64_t undecodable_frames() const { return shown_.undecodable; }
  int64_t dropped_frames() const override { return shown_.dropped; }
  // Pictures skipped as repeats of the one before (not delivered, not dropped).
  int64_t repeated_frames() const { return shown_.repeated; }
  bool uses_times_file() const { return !recorded_.empty(); }
  // Clockwise turn applied to every decoded frame to show it upright: 0, 90, 180 or 270 deg.
  int rotation_deg() const { return rotation_deg_; }
  // Reading ahead, the time each side waited for the other so far, s: Next() for a frame
  // (the decoding is behind), the decoding thread for room in the queue (the consumer is
  // behind). Zero without reading ahead.
  struct QueueWaits {
    double consumer_s = 0, reader_s = 0;
  };
  QueueWaits queue_waits() const;

 private:
  struct Counts {
    int loops = 0;
    bool ended_short = false;
    int64_t repaired = 0, undecodable = 0, dropped = 0, repeated = 0;
  };
  // A frame (none: the end) with the counts after it, or the reason decoding failed.
  struct Produced {
    std::optional<Frame> frame;
    Counts counts;
    std::exception_ptr error;
  };
  void Open();
  void LoadTimes();
  std::optional<Frame> Decode();
  std::optional<Frame> Produce();  // the next frame to deliver: loops, repeats, recorded times
  Produced ProduceCounted();
  void ReadAhead();                 // the decoding thread


  VideoFileSourceConfig config_;
  std::unique_ptr<AvVideoReader> reader_;
  SourceInfo info_;
  std::optional<Frame> pending_;  // decoded ahead (the first frame, read at open)
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
  Counts shown_;         // as of the last frame delivered

  std::thread ahead_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Produced> queue_;
  bool stop_ = false;     // the source is going away: the thread ends
  bool finished_ = false; // the thread has queued its last item
  QueueWaits waits_;      // under mutex_
};

}  // namespace bouncefit
