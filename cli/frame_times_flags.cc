#include "cli/frame_times_flags.h"

namespace bouncefit::cli {

void AddFrameTimesFlags(CLI::App* cmd, bool* retime_frames, bool* keep_frame_times) {
  auto* retime = cmd->add_flag(
      "--retime-frames", *retime_frames,
      "the default: where the ball's arcs show the pictures were taken at a higher rate than "
      "stamped (some dropped: a 24 fps capture saved at 20 fps), read each at the time it was "
      "taken");
  auto* keep = cmd->add_flag("--keep-frame-times", *keep_frame_times,
                             "read every picture at its stamp, even where the ball's arcs show "
                             "pictures were dropped (the run still says so)");
  retime->excludes(keep);
}

FrameTimes FrameTimesMode(bool keep_frame_times) {
  return keep_frame_times ? FrameTimes::kStamped : FrameTimes::kRetimed;
}

}  // namespace bouncefit::cli
