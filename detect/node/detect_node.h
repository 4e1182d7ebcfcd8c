#pragma once
// The detect node: BALL_BOX -> Calibrator + BounceDetector -> CALIBRATION and BOUNCE_PEAK.
//
// A thin adapter around the core (detect/bounce_detector.h). The `detect` command runs it as
// a process of its own (Subscribe + Run); `run` feeds it boxes in-process with OnBox() or
// OnObservation() and gets the same events back (and, with a bus, the same messages out).
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "detect/bounce_detector.h"
#include "detect/frame_retiming.h"
#include "detect/capture_clock_detector.h"
#include "msgs/channels.h"
#include "track/ball_observation.h"
#include "track/node/ball_box_msg.h"

namespace bouncefit {

class LcmBus;

struct DetectNodeConfig {
  Channels channels;
  BounceDetectorConfig detector;
  FrameRetimingConfig retiming;
  // When a drop ends, send its apexes again on BOUNCE_PEAK with their refitted heights
  // (RefittedPeakMsgs). `run` sends them itself (a bounce it heard keeps its flight time).
  bool publish_refits = true;
};

struct DetectStats {
  int64_t boxes = 0;           // BALL_BOX messages handled
  int64_t found = 0;           // ... with the ball found
  int64_t peaks = 0;           // BOUNCE_PEAK published (or returned)
  int64_t calibrations = 0;    // CALIBRATION published (or returned)
  int64_t sequences_ended = 0;
  int64_t stream_restarts = 0; // box times went backwards: a new stream, a fresh detector
  int64_t rejected = 0;        // boxes the detector refused (bad values)
  double detect_s = 0;         // time spent in the detector
};

calibration_t ToCalibrationMsg(const Calibration& c);
bounce_peak_t ToBouncePeakMsg(const BouncePeak& p);
// Drop `d`'s apexes again, each with its height refitted with every arc of the drop when it
// ended (the live one saw only the floor before it; height_px at the live apex's scale),
// `utime` and `emitted_utime` = now_utime, revision 2. Apexes the refit has no height for are left out.
std::vector<bounce_peak_t> RefittedPeakMsgs(const SequenceSummary& d, int64_t now_utime);

class DetectNode {
 public:
  using EventFn = std::function<void(const DetectorEvent&)>;

  // bus may be null (in-process use: nothing is published). Throws std::invalid_argument
  // for an invalid detector config.
  DetectNode(LcmBus* bus, DetectNodeConfig config);

  // Subscribes to the BALL_BOX channel of the bus (standalone process).
  void Subscribe();

  // One box: detects, publishes what came out, calls the event handler, returns the events.
  // Never throws: a box the detector refuses is counted (stats().rejected).
  std::vector<DetectorEvent> OnBox(const ball_box_t& box);
  std::vector<DetectorEvent> OnObservation(const BallObservation& obs);
  // End of stream: closes the drop in progress.
  std::vector<DetectorEvent> Finish();

  // Handles bus traffic until *stop is true, or (exit_after_idle_s > 0) no box came for that
  // long. Uses the wall clock: this is a node, not a core.
  void Run(const std::atomic<bool>* stop, double exit_after_idle_s);

  void set_event_handler(EventFn fn) { on_event_ = std::move(fn); }
  const BounceDetector& detector() const { return detector_->detector(); }
  // Whether the frames' stamps were re-timed to the rate they were taken at (detect/retiming_detector.h).
  const Retiming& retiming() const { return detector_->retiming(); }
  // Slow motion in the stamps: the capture clock and whether the detector reads on it
  // (detect/capture_clock_detector.h).
  const CaptureClockDetector& clock_reader() const { return *detector_; }
  const DetectStats& stats() const { return stats_; }
  // Summaries of every drop ended so far, across stream restarts.
  std::vector<SequenceSummary> Summaries() const;

 private:
  void Publish(const std::vector<DetectorEvent>& events);

  LcmBus* bus_;
  DetectNodeConfig config_;
  std::unique_ptr<CaptureClockDetector> detector_;
  std::vector<SequenceSummary> earlier_summaries_;
  int64_t rejected_before_ = 0;  // by the detectors of earlier streams
  EventFn on_event_;
  DetectStats stats_;
  int64_t last_utime_ = 0;
  bool have_box_ = false;
  int64_t last_box_wall_us_ = 0;
};

}  // namespace bouncefit
