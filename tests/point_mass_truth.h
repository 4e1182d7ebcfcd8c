#pragma once
// The point-mass physics `bouncefit synth` renders, as the ground truth of fitting tests.
#include "model/ball_preset.h"
#include "model/point_mass_drop.h"

namespace bouncefit::testing {

inline PointMassDropResult PointMassTruth(const BallPreset& ball, double drop_height_m,
                                          double end_time_s = 20) {
  PointMassDropConfig c;
  c.ball = ball;
  c.drop_height_m = drop_height_m;
  c.end_time_s = end_time_s;
  return SimulatePointMassDrop(c);
}

}  // namespace bouncefit::testing
