#pragma once
// Pictures taken at one rate and stamped at a lower one (a 24 fps capture saved at 20 fps: one
// picture in six dropped, each stamp up to 1/24 s off its capture). A ball in free flight then
// does not fall on a parabola of its stamps, and the detector, which fits parabolas to time,
// breaks its arcs. The test: the first moving samples are cut into arcs at the impacts (where
// the ball's height turns from falling to rising) and a parabola of time is fitted to each
// arc, with the stamps as they are and with each frame re-timed to the tick of a faster source
// it would have come from (floor(t f + c) / f). The pooled residual says whether a re-timing
// explains the motion by far better (docs/ACCURACY.md, "Frames re-timed by default"), on the
// whole arcs and on their interior (each arc without its first and last samples): dropped
// pictures misplace the ball all along an arc, while a ball smeared over an impact by a 1/40 s
// shutter, a release or a hand misplace it at an arc's ends, and among 130 re-timings one
// absorbs much of that.
// Whole arcs, not four-sample windows: a window's third difference amplifies a pixel of
// tracking noise by the frame rate cubed, and the shared tennis clip cropped by 8 px and
// re-encoded lost its 7x signal that way (1.5x); fitted arcs keep it (5x). A core with no I/O.
//
// Observations pass through while the ball has not moved; from its first moving samples they
// are held until the test decides (a few tenths of a second of flight), then released, always
// as stamped: the caller re-times them (detect/retiming_detector.h, which also re-times the
// ones before the hold, so that a ball held still pins its release on the same clock). Stamps
// that are not evenly spaced (a camera's own clock, a variable frame rate) are taken as they
// are. kStamped (`--keep-frame-times`) only reports, holding nothing.
#include <cmath>
#include <string>
#include <vector>

#include "msgs/frame_time.h"
#include "track/ball_observation.h"

namespace bouncefit {

enum class FrameTimes {
  kStamped,  // test and report only: nothing held, times as stamped
  kRetimed,  // held until the test decides; re-timed when it finds a faster source rate
};

struct FrameRetimingConfig {
  FrameTimes mode = FrameTimes::kRetimed;
  int min_dof = 12;            // degrees of freedom of the fitted arcs before deciding
  double min_gain = 3.0;       // the re-timing must shrink the residual variance this many times
  // ... and explain this much misfit, px (sqrt of the variance it removes): a parabola is not
  // a ball's exact flight (air drag), and among 130 re-timings one absorbs a pixel of that.
  // Dropped pictures misplace a moving ball by its speed times up to a frame: many pixels.
  double min_explained_px = 2.0;
  double min_move_px = 3;      // four samples whose ends are closer: the ball is not moving yet
  int max_held = 60;           // held observations at most; then taken as stamped
  double uniform_tolerance = 0.01;  // stamps evenly spaced within this share of the period
};

struct Retiming {
  bool decided = false;
  bool retimed = false;        // a re-timing explains the flight (the test's verdict)
  bool applied = false;        // retimed, and the detector reads the re-timed times (kRetimed)
  double stamped_fps = 0;      // the rate of the stamps (evenly spaced ones)
  double source_fps = 0;       // retimed: the rate the pictures were taken at
  double phase = 0;            // retimed: c in floor(t f + c) / f
  double rms_as_stamped_px = 0, rms_retimed_px = 0;  // the arcs' parabola residuals
  double gain = 1;             // residual variance as stamped over re-timed (the best)
  int arcs = 0;                // the arcs the test rested on
  std::string verdict;         // one line for the run's output
};

class FrameRetimer {
 public:
  explicit FrameRetimer(FrameRetimingConfig config = {}) : config_(config) {}
  // One observation in stream order; returns those released (in order, possibly none), as
  // stamped.
  std::vector<BallObservation> Push(const BallObservation& obs);
  // End of stream: decides on what was seen and releases what is held.
  std::vector<BallObservation> Flush();
  const Retiming& retiming() const { return retiming_; }
  // The observation at the time it was taken, once the test has found a re-timing (else as is).
  BallObservation Retimed(BallObservation o) const;

 private:
  void Decide(bool enough);
  // Closes the arc being collected (kept when it can be tested: 5 samples at least).
  void CloseArc();
  // Residual degrees of freedom of the arcs collected (and the one open).
  int Dof() const;
  std::vector<BallObservation> Release();

  FrameRetimingConfig config_;
  Retiming retiming_;
  std::vector<BallObservation> held_, recent_;  // recent_: the last consecutive found ones
  bool moving_ = false;                          // the ball has started to move
  std::vector<BallObservation> arc_;              // the arc being collected
  std::vector<std::vector<BallObservation>> arcs_;
  double period_s_ = 0;
  int64_t last_utime_ = -1;
  bool uniform_ = true;
};

}  // namespace bouncefit
