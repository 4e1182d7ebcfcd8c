#pragma once
// When each frame of a synth clip is taken (real time) and how the file stamps it (file
// time). A constant-rate clip has both at i / fps. A phone's slow motion captures at a
// constant high rate and stamps a span of it slowed (each frame `slow_motion` capture periods
// after the one before), the rest in real time, and says so in no tag. A phone's ordinary
// video takes its frames at a rate that wanders (26-30 fps in dim light) and stamps each at
// the time it was taken.
#include <cstdint>
#include <string>
#include <vector>

namespace bouncefit {

struct SynthTimelineConfig {
  double slow_motion = 1;    // frames in [slow_from_s, slow_to_s) of real time stamped this many
                             // capture periods apart (1: none)
  double slow_from_s = 0, slow_to_s = 0;  // real seconds since the clip's first frame
  double slow_ramp_s = 0;    // the slow-down ramps from 1 to slow_motion over this long at
                             // the span's start, and back at its end (inside the span), s
  double vfr_min_fps = 0;    // > 0: each frame interval drawn between 1/fps and 1/vfr_min_fps
  // One line naming what is wrong, or empty.
  std::string Validate(double fps) const;
  bool Variable() const { return slow_motion != 1 || vfr_min_fps > 0; }
};

struct SynthFrameTime {
  double real_s = 0;  // when the frame was taken, s since the first frame
  double file_s = 0;  // its stamp in the file, s since the first frame
};

// The frames of a clip duration_s long in real time (the last one taken before duration_s).
std::vector<SynthFrameTime> SynthFrameTimes(const SynthTimelineConfig& c, double fps,
                                            double duration_s, uint64_t seed);

}  // namespace bouncefit
