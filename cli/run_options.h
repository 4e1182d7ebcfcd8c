#pragma once
// The options of `bouncefit run`, shared by one clip's run (cli/run_command.cc) and the joint
// run of several clips of one ball (cli/run_several.cc).
#include <cstdint>
#include <string>
#include <vector>

#include "cli/ball_flags.h"
#include "cli/clock_flags.h"
#include "cli/scale_flags.h"
#include "fit/fit_models.h"
#include "msgs/channels.h"
#include "pipeline/exit_status.h"
#include "track/tracker.h"

namespace bouncefit::cli {

struct RunOptions {
  std::vector<std::string> clips;  // none: the built-in sample (or --device); several: RunSeveral
  std::string device;
  std::string out = "bouncefit-out";
  bool overwrite = false;  // clear an earlier run's files in --out first
  BallFlags ball;  // no name: the sample's ball, else pingpong
  double speed = 1.0;
  bool quiet = false;
  bool json = false;
  bool no_fit = false;
  bool no_audio = false;
  std::string audio_device;  // ALSA microphone beside --device
  std::string lcm_url = kDefaultLcmUrl;
  Channels channels;
  std::string model = "bullet-softbody";
  std::string method = "nlopt";
  std::string impact = "restitution";  // the final fit's rebound law (docs/MODEL.md)
  int max_evals = 0;  // 0: the session's default
  ScaleFlags scale;
  ClockFlags clock;
  int64_t max_frames = 0;
  TrackerConfig tracker;
  bool pick_window = false;
};

// The fit node's configuration from the run's flags and its resolved ball.
FitSetup FitConfig(const RunOptions& o, const BallPreset& ball);

// One clip, the built-in sample or a camera: track, detect, hear, fit; writes o.out.
// `ball`: the ball already resolved (null: from o.ball, or the sample's).
// Returns what the exit status says (pipeline/exit_status.h); throws for errors.
ExitStatus RunOneClip(RunOptions o, const BallPreset* ball = nullptr);

// Several clips of one ball: each run as `run CLIP --no-fit` into OUT/<k>-<name>/, then their
// drops fitted jointly into OUT (cli/run_several.cc).
ExitStatus RunSeveral(RunOptions o);

}  // namespace bouncefit::cli
