#pragma once
// Finds the ball in one frame. Owned by the tracker issue (#3); the capture node and the
// run command use only this interface.
#include <string>

#include "capture/frame.h"
#include "track/ball_observation.h"

namespace bouncefit {

struct TrackerConfig {
  // Filled in by issue #3 (colour pick, ROI, thresholds, ...).
};

class Tracker {
 public:
  explicit Tracker(TrackerConfig config);
  // Frames must come in capture order; the tracker predicts the next position from them.
  BallObservation Track(const Frame& frame);
  // One line for the user: what colour it locked on and why.
  std::string Describe() const;

 private:
  TrackerConfig config_;
};

}  // namespace bouncefit
