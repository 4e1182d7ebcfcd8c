#pragma once
// The time a picture was taken, from its stamp, where a run re-timed its frames (summary.json's
// clock.frames_retimed, docs/FORMATS.md): on the tick of a source_fps capture, at the
// re-timing's phase. The detector reads its boxes so, and report/ re-times the track the same.
#include <cmath>

namespace bouncefit {

// floor(t f + c) / f, t the stamp in seconds.
inline double TakenAtSeconds(double stamp_s, double source_fps, double phase) {
  return std::floor(stamp_s * source_fps + phase + 1e-9) / source_fps;
}

}  // namespace bouncefit
