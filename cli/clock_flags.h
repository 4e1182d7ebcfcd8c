#pragma once
// The clock a measurement is read in seconds with, as given on `run` and `detect`: the file's
// slow motion (--time-scale) and whether frames stamped at a lower rate than they were taken
// (pictures dropped) are re-timed (detect/retiming_detector.h).
#include <CLI/CLI.hpp>

#include "pipeline/detect_stage.h"

namespace bouncefit::cli {

struct ClockFlags {
  double time_scale = 0;          // real s per stream s (0: the clock decides, see detect/)
  bool retime_frames = false;     // --retime-frames: the default, said explicitly
  bool keep_frame_times = false;  // never re-time them (only say so)
};

// Adds --time-scale, --keep-frame-times and --retime-frames (the last two exclude each other).
void AddClockFlags(CLI::App* cmd, ClockFlags* flags);

// The detect stage reads the clock given.
void SetClock(const ClockFlags& flags, DetectStageConfig* config);

}  // namespace bouncefit::cli
