// bouncefit run: the capture, detect and fit nodes in one process (pipeline/pipeline.h). A
// clip (or the built-in sample, or a camera) is replayed at its recorded pace; every message
// goes out on the bus (so `watch` can attach), each node writes what it owns into the output
// directory, and the terminal follows the session.
#include <fmt/format.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "capture/v4l2_camera.h"
#include "cli/ball_flags.h"
#include "cli/bus_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "cli/output_flags.h"
#include "cli/pick_window.h"
#include "cli/run_console.h"
#include "cli/run_options.h"
#include "cli/sample_clip.h"
#include "cli/stop_signal.h"
#include "cli/tracker_flags.h"
#include "fit/fit_export.h"
#include "model/model_by_name.h"
#include "msgs/msg_json.h"
#include "pipeline/pipeline.h"
#include "replay/video_file_source.h"

namespace bouncefit::cli {
namespace {

// The answer in a few lines: the bounces, the fitted law with its uncertainty, where it went.
std::string Summary(const PipelineOutcome& r, const RunConsole& console, const std::string& out_dir) {
  const stream_t& s = r.stream;
  std::string text = fmt::format("run: {}: {} frames in {:.2f} s, ball in {}, {} dropped", r.status == kExitInterrupted ? "stopped" : "done",
                     s.frames, s.wall_s, s.found, s.dropped);
  std::string heights;
  int rebounds = 0;
  for (const auto& [bounce, h] : console.rows()) {
    heights += fmt::format("{}{} {:.3f}", heights.empty() ? "" : ", ", bounce, h);
    rebounds += bounce > 0;
  }
  text += fmt::format("\nbounces: {} rebounds{}", rebounds, heights.empty() ? "" : "; apex heights to quote, m: " + heights);
  if (r.final_fit) {
    const FitUpdate& f = *r.final_fit;
    std::string law;
    for (const auto& c : f.coefficients) {
      if (c.name != "rebound_restitution" && c.name != "rebound_restitution_per_mps" && c.name != "drag" &&
          c.name != "restitution" && c.name != "restitution_per_mps" && c.name != "drag_coefficient")
        continue;
      law += fmt::format("  {} {:.4g}", c.name, c.value);
      if (!c.bound.empty())  // at a bound: the uncertainty goes one way, into the range
        law += std::isfinite(c.sigma) ? fmt::format(" (at its {} bound, {}{:.2g})", c.bound, c.bound == "lower" ? "+" : "-", c.sigma)
                                      : fmt::format(" (at its {} bound)", c.bound);
      else
        law += c.identifiable && std::isfinite(c.sigma) ? fmt::format(" +- {:.2g}", c.sigma) : " (not identifiable)";
    }
    text += fmt::format("\nfitted ball ({}):{}; residual {:.1f} mm over {} bounces", f.model, law, f.residual_m * 1e3,
                        f.recorded_m.size());
  }
  text += "\nwrote " + out_dir + ": track.csv, peaks.csv, impacts.csv, summary.json, fit.jsonl" +
          (r.final_fit ? ", coefficients.json, fitted_ball/ (Bullet), fitted_ball.glb (Blender)" : "") +
          (std::filesystem::exists(std::filesystem::path(out_dir) / "simulated.csv") ? ", simulated.csv" : "") +
          " (`bouncefit report " + out_dir + "` draws them)";
  if (!s.tracker.empty()) text += "\n" + s.tracker;
  return text;
}

}  // namespace

FitSetup FitConfig(const RunOptions& o, const BallPreset& ball) {
  FitSetup fc;
  fc.ball = ball;
  fc.model = o.model;
  fc.session.method = o.method;
  fc.session.impact = o.impact;
  if (o.max_evals > 0) fc.session.max_evaluations_final = o.max_evals;
  return fc;
}

ExitStatus RunOneClip(RunOptions o, const BallPreset* resolved) {
  RunConsole console(o.json ? ConsoleMode::kJson : o.quiet ? ConsoleMode::kQuiet : ConsoleMode::kHuman, stdout);
  ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
  if (o.pick_window) CheckPickWindowDisplay();  // at once, before anything is rendered or written

  std::string clip = o.clips.empty() ? std::string() : o.clips.front();
  BallFlags named;  // the ball the sample names
  if (clip.empty() && o.device.empty()) {
    const SampleClip sample = BuiltInSample([&](const std::string& s) { console.Info(s); });
    clip = sample.clip.string();
    named.name = sample.ball;
  }
  const BallPreset ball = resolved ? *resolved : ResolveBall(o.ball, named);

  PipelineConfig pc;
  pc.capture.clip = o.device.empty() ? clip : "";
  pc.capture.camera.device = o.device;
  pc.capture.speed = o.speed;
  pc.capture.max_frames = o.max_frames;
  pc.capture.no_audio = o.no_audio;
  pc.capture.audio_device = o.audio_device;
  pc.capture.tracker = o.tracker;
  pc.capture.channels = o.channels;
  if (o.pick_window)
    console.Info(PickOnFirstFrame(
        [&]() -> std::unique_ptr<FrameSource> {
          if (!o.device.empty()) return std::make_unique<V4l2Camera>(pc.capture.camera);
          return std::make_unique<VideoFileSource>(ReadAheadConfig(clip));
        },
        &pc.capture.tracker));
  pc.detect.ball = ball;
  SetScale(o.scale, &pc.detect);
  SetClock(o.clock, &pc.detect);
  pc.detect.channels = o.channels;
  if (!o.no_fit) {
    FitStageConfig fc;
    fc.fit = FitConfig(o, ball);
    fc.channels = o.channels;
    pc.fit = fc;
  }
  pc.lcm_url = o.lcm_url;
  pc.out_dir = o.out;
  pc.overwrite = o.overwrite;
  Pipeline pipeline(pc, [&](const std::string& s) { console.Info(s); });
  console.Follow(pipeline.bus(), o.channels);
  const stream_t& st = pipeline.capture().stream();
  console.Info(fmt::format("run: {}, {:.2f} fps; ball {} ({:.1f} mm, {:.1f} g); output {}; bus {}; sound: {}",
                           st.description, st.nominal_fps, ball.name, ball.diameter_m * 1e3, ball.mass_kg * 1e3,
                           o.out, o.lcm_url, st.sound));

  const std::atomic<bool>& stop = StopOnSignal();
  CaptureStage& capture = pipeline.capture();
  bool final_said = false;
  const PipelineOutcome r = pipeline.Run(
      &stop, [&] { console.Progress(capture.stream_s(), capture.total_s(), capture.frames(), capture.found()); },
      [&](int sims, int budget) {
        if (!final_said) {
          // The thorough fit takes seconds: say so before the silence.
          console.Info(fmt::format("final fit: up to {} simulations on all cores (seconds to a minute)", budget));
          final_said = true;
        }
        console.FitProgress(sims, budget);
      });
  nlohmann::json j = {{"event", "summary"}, {"status", static_cast<int>(r.status)}, {"rows", r.rows}, {"why", r.why}};
  if (r.final_fit) j["final_fit"] = FitUpdateToJson(*r.final_fit, ball);
  console.Summary(Summary(r, console, o.out), j.dump());
  if (r.status == kExitError) throw std::runtime_error(r.why + " (what was recorded is in " + o.out + ")");
  if (r.status != kExitAnswer && r.status != kExitInterrupted)
    std::fprintf(stderr, "bouncefit run: %s\n", r.why.c_str());
  return r.status;
}

void AddRunCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "run",
      "Everything in one process: replay a clip (or the built-in sample) at its recorded pace, "
      "track, calibrate, detect every bounce apex and fit the ball model after each bounce");
  cmd->footer(
      "Examples:\n"
      "  bouncefit run --out out/sample                         # the built-in sample drop\n"
      "  bouncefit run drop.mp4 --ball tennis --out out/drop    # a clip of your own\n"
      "  bouncefit run low.mp4 high.mp4 --ball tennis --out out/both   # two drops, fitted jointly\n"
      "Exit status: 0 an answer was written (a final fit, or the peaks with --no-fit), 1 an error,\n"
      "2 a bad flag (or one the measurement contradicts), 3 no bounce found, 4 bounces but no fit,\n"
      "130 stopped by Ctrl-C or SIGTERM (what was recorded so far is written).");
  auto o = std::make_shared<RunOptions>();
  auto* clip = cmd->add_option("clip", o->clips,
                               "clip to replay (.avi/.mp4/.mov); none: the built-in sample drop; "
                               "several: drops of one ball, each run into OUT/<k>-<name>/, fitted jointly")
                   ->check(CLI::ExistingFile);
  cmd->add_option("--device", o->device, "a V4L2 camera instead of a clip, e.g. /dev/video0")->excludes(clip);
  AddOutputFlags(cmd, &o->out, &o->overwrite, "every file of the run")->capture_default_str();
  AddBallFlags(cmd, &o->ball);
  cmd->add_option("--speed", o->speed, "replay at this multiple of real time (0: as fast as possible)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("--quiet,-q", o->quiet, "print nothing but errors");
  cmd->add_flag("--json", o->json, "print one JSON object per event (calibration, peak, revision, fit, summary)");
  cmd->add_flag("--no-fit", o->no_fit, "track and detect only");
  auto* no_audio = cmd->add_flag("--no-audio", o->no_audio, "ignore the clip's sound track (impacts from the picture only)");
  cmd->add_option("--audio-device", o->audio_device,
                  "with --device: an ALSA microphone heard beside the camera, e.g. hw:1,0 or "
                  "plughw:1,0 (`arecord -l` lists them); impacts heard are published as they happen")
      ->excludes(no_audio)
      ->excludes(clip);
  cmd->add_option("--model", o->model, "model fitted: " + BallModelNames())->capture_default_str();
  cmd->add_option("--method", o->method, "search: nlopt (default) or paper")
      ->check(CLI::IsMember({"nlopt", "paper"}))
      ->capture_default_str();
  cmd->add_option("--impact", o->impact,
                  "the rebound: boost (the paper's extra force on Bullet's own rebound) or "
                  "restitution (the law e(v) = e0 - k v, fitted in two stages); docs/MODEL.md")
      ->check(CLI::IsMember({"boost", "restitution"}))
      ->capture_default_str();
  cmd->add_option("--max-evals", o->max_evals, "simulations for the final fit (0: default)")->check(NonNegative());
  AddScaleFlags(cmd, &o->scale);
  AddClockFlags(cmd, &o->clock);
  cmd->add_option("--max-frames", o->max_frames, "stop after this many frames (0: no limit)")->check(NonNegative());
  AddBusFlags(cmd, &o->lcm_url, &o->channels);
  AddTrackerFlags(cmd, &o->tracker, &o->pick_window);
  cmd->callback([o] {
    const ExitStatus status = o->clips.size() > 1 ? RunSeveral(*o) : RunOneClip(*o);
    if (status != kExitAnswer) throw CLI::RuntimeError(static_cast<int>(status));
  });
}

}  // namespace bouncefit::cli
