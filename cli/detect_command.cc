// bouncefit detect: the detect node as a process of its own (pipeline/detect_stage.h).
// BALL_BOX and IMPACT in; CALIBRATION, BOUNCE_PEAK, IMPACT (seen) and DROP out; prints each
// bounce as it comes.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/ball_flags.h"
#include "cli/bus_flags.h"
#include "cli/clock_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "cli/output_flags.h"
#include "cli/run_console.h"
#include "cli/scale_flags.h"
#include "cli/stop_signal.h"
#include "pipeline/detect_stage.h"
#include "pipeline/exit_status.h"
#include "pipeline/output_dir.h"
#include "model/ball_preset.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"

namespace bouncefit::cli {
namespace {

struct DetectOptions {
  std::string lcm_url = kDefaultLcmUrl;
  Channels channels;
  BallFlags ball;
  ScaleFlags scale;
  ClockFlags clock;
  std::vector<int> frame_size;  // W, H of the camera's picture, px (empty: not known)
  double exit_after_idle_s = 0;
  bool quiet = false;
  std::string out;
  bool overwrite = false;
};

ExitStatus RunDetect(const DetectOptions& o) {
  DetectStageConfig cfg;
  cfg.channels = o.channels;
  cfg.ball = ResolveBall(o.ball);
  SetScale(o.scale, &cfg);
  SetClock(o.clock, &cfg);
  if (o.frame_size.size() == 2) {
    cfg.frame_width_px = o.frame_size[0];
    cfg.frame_height_px = o.frame_size[1];
  }
  if (!o.out.empty()) {
    ClaimOutputDir(o.out, DetectOutputFiles(), o.overwrite);
    cfg.out_dir = o.out;
  }
  LcmBus bus(o.lcm_url);
  RunConsole console(o.quiet ? ConsoleMode::kQuiet : ConsoleMode::kHuman, stdout);
  DetectStage stage(cfg, bus, [&](const std::string& s) { console.Info(s); });
  console.Follow(bus, o.channels, /*fits=*/false);
  console.Info("detect: listening to " + o.channels.ball_box + " and " + o.channels.impact + " on " + o.lcm_url +
               "; publishing " + o.channels.calibration + ", " + o.channels.bounce_peak + " and " + o.channels.drop);
  const std::atomic<bool>& stop = StopOnSignal();

  const auto start = std::chrono::steady_clock::now();
  std::string failure;
  try {
    while (!stop && !stage.done() && stage.fatal().empty()) {
      bus.HandleOnce(50);
      if (o.exit_after_idle_s > 0) {
        const int64_t now = std::chrono::duration_cast<std::chrono::microseconds>(
                                std::chrono::steady_clock::now().time_since_epoch()).count();
        const int64_t since = stage.last_box_wall_us() > 0
                                  ? stage.last_box_wall_us()
                                  : std::chrono::duration_cast<std::chrono::microseconds>(start.time_since_epoch()).count();
        if ((now - since) * 1e-6 > o.exit_after_idle_s) break;
      }
    }
  } catch (const std::exception& e) {
    failure = e.what();
  }
  if (!stage.fatal().empty()) {
    if (!o.out.empty()) RemoveOutputFiles(o.out, DetectOutputFiles());
    throw std::invalid_argument(stage.fatal());
  }
  if (!stage.done()) stage.FinishWithoutEnd();  // stopped, or the capture node went silent
  while (bus.HandleOnce(20)) {
  }  // its own last words, for the console
  std::printf("detect: %s%d boxes, %d bounces (rows of peaks.csv), %lld undecodable, %lld rejected%s\n",
              stop ? "stopped: " : (failure.empty() ? "done: " : "failed: "), stage.boxes(), stage.rows(),
              static_cast<long long>(bus.decode_failures()), static_cast<long long>(bus.handler_failures()),
              o.out.empty() ? "" : ("; wrote " + o.out).c_str());
  if (bus.decode_failures() > 0 && stage.boxes() == 0)
    std::fprintf(stderr, "detect: warning: no BALL_BOX message could be decoded: sent or recorded by another "
                         "version of bouncefit?\n");
  std::fflush(stdout);
  if (!failure.empty()) throw std::runtime_error(failure);
  if (stop) return kExitInterrupted;
  return stage.rebounds() > 0 ? kExitAnswer : kExitNoBounce;
}

}  // namespace

void AddDetectCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "detect",
      "Calibrate and detect bounce apexes from BALL_BOX; publish CALIBRATION and BOUNCE_PEAK");
  auto o = std::make_shared<DetectOptions>();
  AddBusFlags(cmd, &o->lcm_url, &o->channels);
  AddBallFlags(cmd, &o->ball);
  AddScaleFlags(cmd, &o->scale);
  AddClockFlags(cmd, &o->clock);
  cmd->add_option("--frame-size", o->frame_size,
                  "the camera's picture size W,H in px (as `run` knows it): a fall first seen "
                  "just after its vertex, that vertex in the picture, is then known for a "
                  "release the tracker did not see held")
      ->delimiter(',')
      ->expected(2)
      ->check(Positive());
  cmd->add_option("--exit-after-idle", o->exit_after_idle_s,
                  "exit when no box came for this many seconds (0: run until Ctrl-C)");
  cmd->add_flag("--quiet", o->quiet, "print only the summary");
  AddOutputFlags(cmd, &o->out, &o->overwrite, "peaks.csv, impacts.csv, calibration.json and summary.json");
  cmd->footer("Example:\n  bouncefit detect --ball tennis --out out/drop --exit-after-idle 5\n"
              "Exit status: 0 bounces written, 1 an error, 2 a bad flag, 3 no bounce found, 130 stopped.");
  cmd->callback([o] {
    const ExitStatus status = RunDetect(*o);
    if (status != kExitAnswer) throw CLI::RuntimeError(static_cast<int>(status));
  });
}

}  // namespace bouncefit::cli
