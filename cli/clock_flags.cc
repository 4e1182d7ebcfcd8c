#include "cli/clock_flags.h"

#include "cli/number_checks.h"

namespace bouncefit::cli {

void AddClockFlags(CLI::App* cmd, ClockFlags* flags) {
  const std::string group = "Clock";
  cmd->add_option("--time-scale", flags->time_scale,
                  "real seconds per second of the stream's timeline (0.25: a 4x slow-motion "
                  "file; default: as recorded unless the container's capture rate and the "
                  "ball's size agree it is slowed, or the free fall is 16x or 64x weaker than "
                  "the size says: 4x or 8x slow motion that no wrong ball size explains)")
      ->check(NonNegative())
      ->group(group);
  auto* retime = cmd->add_flag(
      "--retime-frames", flags->retime_frames,
      "the default: where the ball's arcs show the pictures were taken at a higher rate than "
      "stamped (some dropped: a 24 fps capture saved at 20 fps), read each at the time it was "
      "taken");
  auto* keep = cmd->add_flag("--keep-frame-times", flags->keep_frame_times,
                             "read every picture at its stamp, even where the ball's arcs show "
                             "pictures were dropped (the run still says so)");
  retime->excludes(keep)->group(group);
  keep->group(group);
}

void SetClock(const ClockFlags& flags, DetectStageConfig* config) {
  config->time_scale = flags.time_scale;
  config->keep_frame_times = flags.keep_frame_times;
}

}  // namespace bouncefit::cli
