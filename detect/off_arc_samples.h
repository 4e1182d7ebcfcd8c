#pragma once
// The samples the current arc turned away, waiting for what they turn out to be: below the
// falling arc and rising (an impact's, once confirmed), or off it otherwise; how many in a
// row the arc missed; and the last detection beyond the ball's reach (a lookalike standing
// still while the ball is unseen is no sample at all).
#include <optional>
#include <vector>

#include "detect/detector_scene.h"

namespace bouncefit {

class OffArcSamples {
 public:
  // A sample off the arc: one more miss in a row.
  void TurnAway(const DetectorSample& s, bool rising);
  // The arc took them, or an arc began: none pending, no misses.
  void Clear();
  // The drop ended: nothing pending, no far detection remembered.
  void Reset();
  void RescaleTime(double k);

  // Every sample pending, in time order.
  std::vector<DetectorSample> InTimeOrder() const;
  // The latest time among t_arc (the arc's last sample) and the samples pending.
  double LastT(double t_arc) const;
  // Whether s, a detection beyond the ball's reach when `far`, lies where the last such one
  // was (within its radius and the gate): something standing still. Remembers s when far.
  bool FarAgain(const DetectorSample& s, bool far, double gate);

  // The rising ones, which an impact may begin the next arc with (the judge drops strays).
  std::vector<DetectorSample>& rising() { return rising_; }
  const std::vector<DetectorSample>& rising() const { return rising_; }
  int misses() const { return misses_; }

 private:
  std::vector<DetectorSample> rising_, other_;
  int misses_ = 0;  // consecutive samples off the current arc
  std::optional<DetectorSample> last_far_;  // the previous sample, when it lay beyond the ball's reach
};

}  // namespace bouncefit
