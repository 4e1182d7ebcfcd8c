#pragma once
// The clock and the scale in words: what the free fall and the ball's size say of the file's
// timeline, said once and again only when it changes (the detect node's notices).
#include <string>

#include "detect/calibrator.h"

namespace bouncefit {

struct ContainerClockWords {
  double capture_fps = 0;  // a slow-motion file's capture rate (0: the file does not say)
  double stored_fps = 0;
  std::string tag;
};

class ClockReport {
 public:
  // forced: the time scale came from --time-scale, not from the file or the detector.
  ClockReport(ContainerClockWords container, bool forced) : container_(container), forced_(forced) {}
  // The line to say for this calibration; empty when nothing new (the scales agree as before).
  std::string Update(const Calibration& c);
  const std::string& last() const { return text_; }

 private:
  ContainerClockWords container_;
  bool forced_;
  std::string text_;  // the latest words (summary.json's clock.report)
  std::string kind_;  // what they said last: clock, scale's source, agreement
};

}  // namespace bouncefit
