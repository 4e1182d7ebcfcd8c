// bouncefit detect: the detect node as a process of its own. BALL_BOX in, CALIBRATION and
// BOUNCE_PEAK out; prints each peak as it comes, and a summary of every drop at the end.
#include <signal.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/bus_flags.h"
#include "cli/frame_times_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "detect/node/detect_node.h"
#include "model/ball_preset.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"

namespace bouncefit::cli {
namespace {

struct DetectOptions {
  std::string lcm_url = kDefaultLcmUrl;
  Channels channels;
  std::string ball;
  double ball_diameter_m = 0;
  double px_per_m = 0;
  double time_scale = 0;
  bool retime_frames = false;
  bool keep_frame_times = false;
  std::vector<int> frame_size;  // W, H of the camera's picture, px (empty: not known)
  double drop_height_m = 0;
  double exit_after_idle_s = 0;
  bool quiet = false;
};

std::atomic<bool> g_stop{false};
extern "C" void OnDetectSignal(int) { g_stop = true; }

void PrintEvent(const DetectorEvent& e, bool quiet) {
  switch (e.kind) {
    case DetectorEvent::Kind::kPeak: {
      const BouncePeak& p = e.peak;
      const double lag_ms = (p.emitted_utime - p.apex_utime) * 1e-3;
      std::printf("peak  seq %d bounce %2d: %.4f m +- %.4f m (%.1f px), apex at %.4f s, "
                  "emitted %.1f ms after it\n",
                  p.sequence, p.bounce, p.height_m, p.height_sigma_m, p.height_px,
                  p.apex_utime * 1e-6, lag_ms);
      break;
    }
    case DetectorEvent::Kind::kCalibration: {
      if (quiet) break;
      const Calibration& c = e.calibration;
      char diameter[96] = "";
      if (c.diameter_ratio > 0)
        std::snprintf(diameter, sizeof diameter, ", ball diameter %.1f%% of the given one",
                      c.diameter_ratio * 100);
      const double deg = 180 / std::numbers::pi;
      std::printf("calib %s: %.2f +- %.2f px/m, roll %.3f +- %.3f deg, floor %.1f +- %.1f px%s\n",
                  c.method.c_str(), c.px_per_m, c.px_per_m_sigma, c.roll_rad * deg,
                  c.roll_sigma_rad * deg, c.floor_px, c.floor_sigma_px, diameter);
      break;
    }
    case DetectorEvent::Kind::kImpact:
      if (quiet) break;
      std::printf("impact seq %d #%d at %.4f s: %.3f m/s in, %.3f m/s out, e = %.3f\n",
                  e.impact.sequence, e.impact.index, e.impact.utime * 1e-6,
                  e.impact.speed_in_mps, e.impact.speed_out_mps, e.impact.restitution);
      break;
    case DetectorEvent::Kind::kSequenceEnd:
      std::printf("end of drop: %s\n", e.reason.c_str());
      break;
  }
  std::fflush(stdout);
}

void PrintSummary(const SequenceSummary& s) {
  std::printf("drop %d (%s): %zu peaks\n", s.sequence, s.end_reason.c_str(), s.peaks.size());
  for (size_t b = 0; b < s.final_height_m.size(); ++b) {
    std::printf("  bounce %2zu: %.4f m", b, s.final_height_m[b]);
    if (b < s.flight_height_m.size() && std::isfinite(s.flight_height_m[b]))
      std::printf(", from flight time %.4f m", s.flight_height_m[b]);
    std::printf("\n");
  }
  for (const auto& i : s.impacts)
    std::printf("  impact %2d: %.3f m/s, restitution %.3f\n", i.index, i.speed_in_mps,
                i.restitution);
  if (std::isfinite(s.restitution_slope_per_mps))
    std::printf("  restitution trend: e = %.3f %+.4f * v (v in m/s)\n",
                s.restitution_intercept, s.restitution_slope_per_mps);
}

void RunDetect(const DetectOptions& o) {
  DetectNodeConfig cfg;
  cfg.channels = o.channels;
  if (!o.ball.empty()) cfg.detector.calibration.ball_diameter_m = ResolveBallPreset(o.ball).diameter_m;
  if (o.ball_diameter_m > 0) cfg.detector.calibration.ball_diameter_m = o.ball_diameter_m;
  cfg.detector.calibration.px_per_m = o.px_per_m;
  cfg.detector.calibration.drop_height_m = o.drop_height_m;
  cfg.detector.time_scale = o.time_scale;
  cfg.retiming.mode = FrameTimesMode(o.keep_frame_times);
  if (o.frame_size.size() == 2) {
    cfg.detector.image_width_px = o.frame_size[0];
    cfg.detector.image_height_px = o.frame_size[1];
  }
  std::string error;
  if (!cfg.detector.IsValid(&error)) throw std::invalid_argument(error);

  LcmBus bus(o.lcm_url);
  DetectNode node(&bus, cfg);
  node.set_event_handler([&o](const DetectorEvent& e) { PrintEvent(e, o.quiet); });
  node.Subscribe();
  if (!o.quiet) {
    std::printf("detect: listening to %s on %s; publishing %s and %s\n",
                o.channels.ball_box.c_str(), o.lcm_url.c_str(), o.channels.calibration.c_str(),
                o.channels.bounce_peak.c_str());
    std::fflush(stdout);
  }
  struct sigaction sa {};
  sa.sa_handler = OnDetectSignal;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);

  std::string failure;
  try {
    node.Run(&g_stop, o.exit_after_idle_s);
  } catch (const std::exception& e) {
    failure = e.what();
  }
  node.Finish();
  for (const auto& s : node.Summaries()) PrintSummary(s);
  const DetectStats& st = node.stats();
  std::printf("detect: %s%lld boxes (%lld found), %lld peaks, %lld calibrations, "
              "%lld undecodable, %lld rejected, detector %.3f s\n",
              g_stop ? "stopped: " : (failure.empty() ? "done: " : "failed: "),
              static_cast<long long>(st.boxes), static_cast<long long>(st.found),
              static_cast<long long>(st.peaks), static_cast<long long>(st.calibrations),
              static_cast<long long>(bus.decode_failures()),
              static_cast<long long>(st.rejected + bus.handler_failures()), st.detect_s);
  if (bus.decode_failures() > 0 && st.boxes == 0)
    std::fprintf(stderr, "detect: warning: no BALL_BOX message could be decoded: sent or recorded by another "
                         "version of bouncefit? (ball_box_t gained camera_dx, camera_dy on 28 Nov 2026)\n");
  std::fflush(stdout);
  if (!failure.empty()) throw std::runtime_error(failure);
}

}  // namespace

void AddDetectCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "detect",
      "Calibrate and detect bounce apexes from BALL_BOX; publish CALIBRATION and BOUNCE_PEAK");
  auto o = std::make_shared<DetectOptions>();
  AddBusFlags(cmd, &o->lcm_url, &o->channels);
  cmd->add_option("--ball", o->ball,
                  "ball preset, for the diameter cross-check (" + BallPresetNames() + ")");
  cmd->add_option("--ball-diameter", o->ball_diameter_m,
                  "ball diameter in metres, for the cross-check (overrides --ball's)");
  auto* ppm = cmd->add_option("--px-per-m", o->px_per_m,
                              "image scale in px per metre (default: from free fall)");
  auto* dh = cmd->add_option("--drop-height", o->drop_height_m,
                             "release height of the ball bottom in metres: scale from it");
  ppm->excludes(dh);
  cmd->add_option("--time-scale", o->time_scale,
                  "real seconds per second of the boxes' timestamps (0.25: a 4x slow-motion "
                  "file; default: as recorded)")
      ->check(NonNegative());
  AddFrameTimesFlags(cmd, &o->retime_frames, &o->keep_frame_times);
  cmd->add_option("--frame-size", o->frame_size,
                  "the camera's picture size W,H in px (as `run` knows it): a fall first seen "
                  "just after its vertex, that vertex in the picture, is then known for a "
                  "release the tracker did not see held")
      ->delimiter(',')
      ->expected(2)
      ->check(Positive());
  cmd->add_option("--exit-after-idle", o->exit_after_idle_s,
                  "exit when no box came for this many seconds (0: run until Ctrl-C)");
  cmd->add_flag("--quiet", o->quiet, "print only peaks and the summary");
  cmd->callback([o] { RunDetect(*o); });
}

}  // namespace bouncefit::cli
