#include "cli/frame_times_flags.h"

namespace bouncefit::cli {

void AddFrameTimesFlags(CLI::App* cmd, bool* retime_frames, bool* keep_frame_times) {
  auto* retime = cmd->add_flag(
      "--retime-frames", *retime_frames,
      "the pictures were taken at a higher rate than their stamps say (some dropped: a 24 fps "
      "capture saved at 20 fps): read each at the time it was taken whenever the ball's flight "
      "shows that rate (default: only when gravity then agrees with the ball's size and did not "
      "as stamped)");
  auto* keep = cmd->add_flag("--keep-frame-times", *keep_frame_times,
                             "read every picture at its stamp, even where the ball's flight and "
                             "size say pictures were dropped (the run still says so)");
  retime->excludes(keep);
}

FrameTimes FrameTimesMode(bool retime_frames, bool keep_frame_times) {
  if (retime_frames) return FrameTimes::kRetimed;
  return keep_frame_times ? FrameTimes::kStamped : FrameTimes::kAuto;
}

}  // namespace bouncefit::cli
