#pragma once
// Pictures taken at one rate and stamped at a lower one (a 24 fps capture saved at 20 fps: one
// picture in six dropped, each stamp up to 1/24 s off its capture). A ball in free flight then
// does not fall on a parabola of its stamps, and the detector, which fits parabolas to time,
// breaks its arcs. The test: a parabola's third divided difference (height over four
// consecutive times) is zero; its median over the first moving samples, with the stamps as
// they are and with each frame re-timed to the tick of a faster source it would have come
// from (floor(t f + c) / f), says whether a re-timing explains the motion by far better
// (docs/ACCURACY.md, "Why tennis_door sees 1 rebound"). A core with no I/O.
//
// By default the test only reports (every observation passes through as stamped): on the
// shared football clip the re-timed flight shows two hops of 3-4.5 cm more than a person
// counts, so re-timing waits for the user's word (`--retime-frames`). Applied, observations
// pass through while the ball has not moved; from its first moving samples they are held
// until the test decides (a few tenths of a second of flight), then released, re-timed or
// not, and every later one goes straight through. Stamps that are not evenly spaced (a
// camera's own clock, a variable frame rate) are taken as they are.
#include <string>
#include <vector>

#include "track/ball_observation.h"

namespace bouncefit {

struct FrameRetimingConfig {
  bool apply = false;          // false: test and report only, times as stamped
  int min_windows = 12;        // moving four-sample windows before deciding
  double min_gain = 3.0;       // the re-timing must shrink the median this many times
  double min_move_px = 3;      // a window whose ends are closer is not moving
  int max_held = 60;           // held observations at most; then taken as stamped
  double uniform_tolerance = 0.01;  // stamps evenly spaced within this share of the period
};

struct Retiming {
  bool decided = false;
  bool retimed = false;        // a re-timing explains the flight (applied only if config.apply)
  double source_fps = 0;       // retimed: the rate the pictures were taken at
  double phase = 0;            // retimed: c in floor(t f + c) / f
  double median_as_stamped = 0, median_retimed = 0;  // px/s^3
  int windows = 0;
  std::string verdict;         // one line for the run's output
};

class FrameRetimer {
 public:
  explicit FrameRetimer(FrameRetimingConfig config = {}) : config_(config) {}
  // One observation in stream order; returns those released (in order, possibly none).
  std::vector<BallObservation> Push(const BallObservation& obs);
  // End of stream: decides on what was seen and releases what is held.
  std::vector<BallObservation> Flush();
  const Retiming& retiming() const { return retiming_; }

 private:
  void Decide(bool enough);
  BallObservation Applied(BallObservation o) const;  // re-timed when decided and applied
  std::vector<BallObservation> Release();

  FrameRetimingConfig config_;
  Retiming retiming_;
  std::vector<BallObservation> held_, recent_;  // recent_: the last consecutive found ones
  std::vector<std::vector<BallObservation>> windows_;
  double period_s_ = 0;
  int64_t last_utime_ = -1;
  bool uniform_ = true;
};

}  // namespace bouncefit
