#pragma once
// The cores' structs as the messages the stages send, and back: the one place where a
// tracker observation, a calibration, a bounce or a fit update becomes its LCM message.
#include <cstdint>
#include <vector>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "detect/calibrator.h"
#include "detect/detector_events.h"
#include "fit/fit_session.h"
#include "track/ball_observation.h"

namespace bouncefit {

// BallObservation and ball_box_t carry the same fields under the same names: one copy
// serves both directions.
template <class To, class From>
To CopyBallBoxFields(const From& f) {
  To t{};
  t.utime = f.utime;
  t.frame = f.frame;
  t.found = f.found;
  t.camera_dx = f.camera_dx;
  t.camera_dy = f.camera_dy;
  if (f.found) {  // a frame without the ball carries zeros
    t.x = f.x;
    t.y = f.y;
    t.w = f.w;
    t.h = f.h;
    t.cx = f.cx;
    t.cy = f.cy;
    t.radius_px = f.radius_px;
    t.pixel_count = f.pixel_count;
    t.aspect_ratio = f.aspect_ratio;
    t.score = f.score;
  }
  return t;
}

inline ball_box_t ToBallBox(const BallObservation& obs) { return CopyBallBoxFields<ball_box_t>(obs); }
inline BallObservation FromBallBox(const ball_box_t& box) { return CopyBallBoxFields<BallObservation>(box); }

calibration_t ToCalibrationMsg(const Calibration& c);
// A bounce as first emitted: revision 0, no refit or fused height yet.
bounce_peak_t ToBouncePeakMsg(const BouncePeak& p);
// Drop `d`'s apexes again, each with its height refitted with every arc of the drop when it
// ended (the live one saw only the floor before it; height_px at the live apex's scale),
// `utime` and `emitted_utime` = now_utime, revision 2. Apexes the refit has no height for are left out.
std::vector<bounce_peak_t> RefittedPeakMsgs(const SequenceSummary& d, int64_t now_utime);

fit_update_t ToFitUpdateMsg(const FitUpdate& update);
// What the fit takes of a bounce: its height and sigma, its times in seconds.
PeakInput ToPeakInput(const bounce_peak_t& peak);

}  // namespace bouncefit
