#pragma once
// The capture node: FrameSource -> Tracker (with its look back) -> one ball_box_t per frame on
// BALL_BOX, in frame order; a frame without the ball may come out a little after the frames
// read after it (track/look_back_tracker.h).
//
// It cannot tell a camera from a file. Pacing (real time for replayed files), recording the
// frames (--record) and logging the published messages (--log) are optional hooks, so the
// `capture` command runs it as a process of its own and `run` can drive it in-process, frame
// by frame, with Step().
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "bouncefit/ball_box_t.hpp"
#include "capture/frame_recorder.h"
#include "capture/frame_source.h"
#include "msgs/channels.h"
#include "track/node/ball_box_msg.h"
#include "track/ball_observation.h"
#include "track/look_back_tracker.h"
#include "track/tracker.h"

namespace bouncefit {

class LcmBus;
class LcmLogRecorder;

struct CaptureNodeConfig {
  Channels channels;
  int64_t max_frames = 0;  // stop after this many frames (0: until the source ends)
};

struct CaptureStats {
  int64_t frames = 0;         // frames read and tracked
  int64_t found = 0;          // frames where the ball was found
  int64_t dropped = 0;        // frames the source lost (sequence gaps)
  int64_t published = 0;      // BALL_BOX messages sent
  int64_t publish_failures = 0;
  int64_t first_utime = 0;    // capture times of the first and last frame
  int64_t last_utime = 0;
  double wall_s = 0;          // since the first frame was read
  double read_s = 0;          // time spent reading/decoding frames
  double track_s = 0;         // time spent in the tracker
  int64_t max_late_us = 0;    // worst lateness against the pacer's schedule
  double stream_s() const { return (last_utime - first_utime) * 1e-6; }
};


class CaptureNode {
 public:
  // Waits until a frame captured at utime is due; returns how late it already is, us.
  using PaceFn = std::function<int64_t(int64_t utime)>;
  // Called for every frame with what the tracker made of it (in-process consumers).
  using ObserverFn = std::function<void(const Frame&, const BallObservation&)>;

  // bus may be null (nothing published: in-process use); the others are optional too.
  CaptureNode(FrameSource& source, Tracker& tracker, LcmBus* bus, CaptureNodeConfig config);

  void set_pacer(PaceFn pace) { pace_ = std::move(pace); }
  void set_recorder(FrameRecorder* recorder) { recorder_ = recorder; }
  void set_log(LcmLogRecorder* log) { log_ = log; }
  void set_observer(ObserverFn observer) { observer_ = std::move(observer); }

  // One frame: read, pace, record, track; publish the frames it settles. False at the end of
  // the stream (or after max_frames), once the frames still waiting are published. Throws
  // what the source or the tracker throws (std::runtime_error, std::invalid_argument), after
  // publishing the frames waiting; what was already published, recorded and logged stays.
  bool Step();
  // The end (or a stop): publishes the frames still waiting; Step() is false after it.
  void Finish();

  // Steps until the end, until *stop becomes true (Ctrl-C), or until max_frames; calls
  // progress about every progress_period_s seconds of wall time.
  const CaptureStats& Run(const std::atomic<bool>* stop = nullptr,
                          const std::function<void(const CaptureStats&)>& progress = {},
                          double progress_period_s = 1.0);

  const CaptureStats& stats() const { return stats_; }

 private:
  // Publishes a settled frame and counts it.
  void Publish(const TrackedFrame& f);

  FrameSource& source_;
  LookBackTracker tracker_;
  LcmBus* bus_;
  CaptureNodeConfig config_;
  PaceFn pace_;
  FrameRecorder* recorder_ = nullptr;
  LcmLogRecorder* log_ = nullptr;
  ObserverFn observer_;
  CaptureStats stats_;
  int64_t start_wall_us_ = -1;
  bool ended_ = false;
  std::vector<uint8_t> buffer_;
};

}  // namespace bouncefit
