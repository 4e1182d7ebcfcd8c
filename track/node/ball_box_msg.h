#pragma once
// BallObservation (the tracker core's output) <-> ball_box_t (its message on BALL_BOX).
// The two carry the same fields under the same names: one copy serves both directions.
#include "bouncefit/ball_box_t.hpp"
#include "track/ball_observation.h"

namespace bouncefit {

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

inline ball_box_t ToBallBox(const BallObservation& obs) {
  return CopyBallBoxFields<ball_box_t>(obs);
}
inline BallObservation FromBallBox(const ball_box_t& box) {
  return CopyBallBoxFields<BallObservation>(box);
}

}  // namespace bouncefit
