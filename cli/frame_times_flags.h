#pragma once
// The frame-time flags, shared by `run` and `detect`: whether frames stamped at a lower rate
// than they were taken (pictures dropped) are re-timed (detect/retiming_detector.h).
#include <CLI/CLI.hpp>

#include "detect/frame_retiming.h"

namespace bouncefit::cli {

// Adds --keep-frame-times, and --retime-frames (the default, said explicitly; they exclude
// each other), writing into the two flags.
void AddFrameTimesFlags(CLI::App* cmd, bool* retime_frames, bool* keep_frame_times);

FrameTimes FrameTimesMode(bool keep_frame_times);

}  // namespace bouncefit::cli
