#pragma once
// The bounce detector behind the frame-time test (detect/frame_retiming.h) and the capture
// clock (detect/capture_clock.h).
//
// Stamps that show a slowed stretch (a phone's slow motion) may be read on the capture clock
// first (detect/capture_clock_detector.h decides): each picture at the time it was taken; the
// frame-time test then sees those times.
// Pictures taken at one rate and stamped at a lower one: once the test finds the faster rate
// the pictures came from, every observation is read at the time it was taken, the ones seen
// before the test decided too (a fresh detector reads them again, re-timed; what the first one
// emitted on them stands). The ball held still before a drop pins its release time, so it
// must be on the clock of its fall: with the hold as stamped and the fall re-timed, a rendered
// 1 m drop taken at 24 fps and stamped at 20 fps measured its release 0.859 m and its first
// calibration 19% off; read whole, 1.0005 m (docs/ACCURACY.md "Frames re-timed by default").
// A core with no I/O.
#include <deque>
#include <limits>
#include <memory>
#include <vector>

#include "detect/bounce_detector.h"
#include "detect/capture_clock.h"
#include "detect/frame_retiming.h"
#include "track/ball_observation.h"

namespace bouncefit {

class RetimingDetector {
 public:
  // Throws std::invalid_argument for an invalid detector config.
  // on_capture_clock: slowed steps are read as one capture period each (else as stamped).
  RetimingDetector(BounceDetectorConfig detector, FrameRetimingConfig retiming,
                   CaptureClockConfig capture = {}, bool on_capture_clock = false);

  // One observation in stream order; returns the events released by it. An observation the
  // detector refuses (bad values) is counted in rejected(), never thrown.
  std::vector<DetectorEvent> Push(const BallObservation& obs);
  // End of stream: decides what is still open and closes the drop in progress.
  std::vector<DetectorEvent> Finish();

  const BounceDetector& detector() const { return *detector_; }
  // The frame-time test's verdict, and whether the detector reads re-timed times.
  const Retiming& retiming() const { return retimer_.retiming(); }
  // The capture clock the observations were read on (no slowed steps: as stamped).
  const CaptureClock& capture_clock() const { return capture_; }
  int64_t rejected() const { return rejected_; }

 private:
  void Feed(const BallObservation& o, std::vector<DetectorEvent>* out);
  // The test has decided: on a re-timing, a fresh detector reads the history so far re-timed.
  void OnDecided();

  BounceDetectorConfig detector_config_;
  CaptureClock capture_;
  bool on_capture_clock_;
  int64_t last_stamp_ = std::numeric_limits<int64_t>::min();
  FrameRetimer retimer_;
  std::unique_ptr<BounceDetector> detector_;
  // What the detector read before the test decided (the ball still, before its first moves),
  // the last kMaxBefore only.
  std::deque<BallObservation> before_;
  static constexpr size_t kMaxBefore = 1000;
  int64_t rejected_ = 0;
};

}  // namespace bouncefit
