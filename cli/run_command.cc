// bouncefit run: every node in one process. A clip (or the built-in sample, or a camera) is
// replayed at its recorded pace through the tracker, the detector and the fitter; every
// message goes out on the bus (so `watch` can attach), into the output directory, and onto
// the terminal as it happens.
#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>

#include "capture/v4l2_camera.h"
#include "cli/bus_flags.h"
#include "cli/frame_times_flags.h"
#include "cli/commands.h"
#include "cli/fit_offline.h"
#include "cli/number_checks.h"
#include "cli/pick_window.h"
#include "cli/run_console.h"
#include "cli/run_options.h"
#include "cli/run_output.h"
#include "cli/run_sound.h"
#include "cli/sample_clip.h"
#include "cli/tracker_flags.h"
#include "detect/node/detect_node.h"
#include "fit/fit_export.h"
#include "fit/node/fit_node.h"
#include "model/model_by_name.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"
#include "msgs/msg_json.h"
#include "replay/container_clock.h"
#include "replay/pacer.h"
#include "replay/video_file_source.h"
#include "track/node/capture_node.h"

namespace bouncefit::cli {
namespace {


std::atomic<bool> g_stop{false};
extern "C" void OnRunSignal(int) { g_stop = true; }

std::string Fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// What the drops' ends learnt of each peak the picture emitted: its refitted and flight-time
// heights (NaN: none).
std::vector<RunSound::AfterRefit> AfterRefitOf(const std::vector<bounce_peak_t>& peaks,
                                               const std::vector<SequenceSummary>& summaries) {
  std::vector<RunSound::AfterRefit> out(peaks.size());
  for (size_t i = 0; i < peaks.size(); ++i)
    for (const auto& d : summaries)
      if (d.sequence == peaks[i].sequence) {
        out[i].refit_m = d.FinalHeightOf(peaks[i].bounce);
        out[i].flight_m = d.FlightHeightOf(peaks[i].bounce);
      }
  return out;
}

// "; refitted with the whole drop, m: 1 0.733, 2 0.515, ..." for the apexes a drop emitted
// (the heights to quote: the live ones saw only the floor before them).
std::string RefitHeights(const SequenceSummary& d) {
  std::string line;
  for (const BouncePeak& p : d.peaks) {
    const double h = d.FinalHeightOf(p.bounce);
    if (std::isfinite(h)) line += (line.empty() ? " " : ", ") + std::to_string(p.bounce) + " " + Fixed(h, 3);
  }
  return line.empty() ? line : "; refitted with the whole drop, m:" + line;
}

// Fit updates arrive on the fitter's thread; the main loop publishes and records them, so
// the bus, the files and the terminal are only ever touched from one thread.
class FitInbox {
 public:
  void Push(const fit_update_t& m, const FitUpdate& u) {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.emplace_back(m, u);
  }
  std::deque<std::pair<fit_update_t, FitUpdate>> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(queue_, {});
  }

 private:
  std::mutex mutex_;
  std::deque<std::pair<fit_update_t, FitUpdate>> queue_;
};

std::unique_ptr<FrameSource> OpenSource(const RunOptions& o, const std::string& clip) {
  if (!o.device.empty()) {
    V4l2CameraConfig c;
    c.device = o.device;
    return std::make_unique<V4l2Camera>(c);
  }
  return std::make_unique<VideoFileSource>(ReadAheadConfig(clip));
}

// The clock against the ball's size, said once per change: the two scales' agreement, and
// slow motion when the detector switched to it.
struct ClockReport {
  std::string text;  // the last line said
  double q = 0, time_scale = 0;
};

// forced: the time scale came from --time-scale, not from the file or the detector.
void ReportClock(const Calibration& c, const ContainerClock& container, bool forced,
                 ClockReport* last, RunConsole& console) {
  const double q = c.gravity_over_size;
  if (!(q > 0)) return;
  if (last->q > 0 && last->time_scale == c.time_scale && std::abs(q / last->q - 1) < 0.05) return;
  std::string r;
  if (c.time_scale != 1) {
    r = "clock: slow motion: the file plays " + Fixed(1 / c.time_scale, 2) +
        "x slower than real time";
    if (container.capture_fps > 0)
      r += " (" + container.tag + " " + Fixed(container.capture_fps, 0) + " fps, stored at " +
           Fixed(container.stored_fps, 2) + " fps)";
    else if (c.time_scale < 1 && !forced)
      r += " (the file does not say so; the free fall against the ball's size does, by more "
           "than a ball of another preset would: --time-scale 1 to read it as recorded)";
    r += "; times and heights use real time; gravity's scale is " + Fixed(q, 2) +
         "x the ball size's";
    if (std::abs(std::log(q)) > std::log(1.3) && c.diameter_ratio > 0)
      r += " (the ball measures " + Fixed(c.diameter_ratio, 2) +
           "x the size given on the free fall's scale: another ball than the preset?)";
  } else if (c.method == "ball-diameter" && c.free_fall_px_per_m > 0) {
    // Too uncertain to say anything about the clock: no slow motion to suggest.
    r = "clock: as recorded; the free fall is not measured (its scale " + Fixed(c.free_fall_px_per_m, 0) +
        " +- " + Fixed(c.free_fall_sigma, 0) + " px/m): heights use the ball's size, " +
        Fixed(c.px_per_m, 0) + " px/m";
  } else {
    r = "clock: as recorded; gravity's scale is " + Fixed(q, 2) + "x the ball size's";
    if (std::abs(std::log(q)) > std::log(1.3))
      r += " (they disagree: a ball of another size than given, or a timeline slowed " +
           Fixed(1 / std::sqrt(q), 2) + "x: --time-scale " + Fixed(std::sqrt(q), 3) +
           " if so)";
  }
  *last = {r, q, c.time_scale};
  console.Info(r);
}

// Flags that need the frame size, checked before anything is written.
void ValidateAgainstFrame(const TrackerConfig& t, const SourceInfo& info) {
  if (info.width <= 0 || info.height <= 0) return;
  const std::string size = std::to_string(info.width) + "x" + std::to_string(info.height);
  if (t.has_pick && !(t.pick_x >= 0 && t.pick_x < info.width && t.pick_y >= 0 &&
                      t.pick_y < info.height))
    throw std::invalid_argument("--pick " + Fixed(t.pick_x, 0) + "," + Fixed(t.pick_y, 0) +
                                " is outside the " + size + " px frame");
  if (t.roi_w > 0 && t.roi_h > 0 &&
      (t.roi_x < 0 || t.roi_y < 0 || t.roi_x >= info.width || t.roi_y >= info.height))
    throw std::invalid_argument("--roi starts outside the " + size + " px frame");
}

// The model's trajectory with the final coefficients, on the stream clock, for Fig. 7.
void WriteSimulatedTrajectory(const RunOutput& out, const FitNode& fit, const FitUpdate& u,
                              int64_t release_utime) {
  SimulationOptions so;
  so.drop_height_m = u.drop_height_m;
  so.record_trajectory = true;
  so.duration_s = 8.0;
  const SimulationResult r = fit.model().Simulate(u.values, so);
  if (!r.ok) return;
  WriteSimulatedCsv(out.dir(), SecondsSince(release_utime, out.stream_start()), r.trajectory);
}

}  // namespace

FitNodeConfig FitConfig(const RunOptions& o) {
  FitNodeConfig fc;
  fc.ball = o.ball;
  fc.mass_kg = o.mass_kg;
  fc.diameter_m = o.diameter_m;
  fc.model = o.model;
  fc.session.method = o.method;
  fc.session.impact = o.impact;
  if (o.max_evals > 0) fc.session.max_evaluations_final = o.max_evals;
  fc.channels = o.channels;
  return fc;
}

void RunOneClip(RunOptions o) {
  if (!o.audio_device.empty() && o.device.empty())
    throw std::invalid_argument("--audio-device needs --device (a clip's own sound track is used)");
  Pacer pacer(o.speed);  // validates --speed
  RunConsole console(o.json ? ConsoleMode::kJson : o.quiet ? ConsoleMode::kQuiet
                                                           : ConsoleMode::kHuman,
                     stdout);
  ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
  if (o.pick_window) CheckPickWindowDisplay();  // at once, before anything is rendered or written

  std::string clip = o.clips.empty() ? std::string() : o.clips.front();
  if (clip.empty() && o.device.empty()) {
    const SampleClip sample = BuiltInSample([&](const std::string& s) { console.Info(s); });
    clip = sample.clip.string();
    if (o.ball.empty()) o.ball = sample.ball;
  }
  if (o.ball.empty()) o.ball = "pingpong";
  const BallPreset ball = ResolveBallPreset(o.ball, o.diameter_m, o.mass_kg);

  if (o.pick_window) console.Info(PickOnFirstFrame([&] { return OpenSource(o, clip); }, &o.tracker));
  std::unique_ptr<FrameSource> source = OpenSource(o, clip);
  const SourceInfo info = source->Info();
  const bool is_file = o.device.empty();
  ValidateAgainstFrame(o.tracker, info);  // before any output exists
  Tracker tracker(o.tracker);
  LcmBus bus(o.lcm_url);
  RunOutput out(o.out);

  CaptureNodeConfig cc;
  cc.channels = o.channels;
  cc.max_frames = o.max_frames;
  CaptureNode capture(*source, tracker, &bus, cc);
  capture.set_log(&out.log());
  if (is_file && o.speed > 0) capture.set_pacer([&pacer](int64_t t) { return pacer.WaitFor(t); });

  std::unique_ptr<RunSound> sound_owner =
      !o.audio_device.empty()
          ? std::make_unique<RunSound>(AlsaMicrophoneConfig{.device = o.audio_device, .config_text = {}}, ball)
          : std::make_unique<RunSound>(is_file && !o.no_audio ? clip : "", ball);
  RunSound& sound = *sound_owner;
  auto publish_impact = [&](const impact_t& m) {
    bus.Publish(o.channels.impact, m);
    out.Log(o.channels.impact, m);
  };

  DetectNodeConfig dc;
  dc.channels = o.channels;
  dc.publish_refits = false;  // sent below, but for the bounces heard end to end
  dc.detector.calibration.ball_diameter_m = ball.diameter_m;
  dc.detector.calibration.px_per_m = o.px_per_m;
  dc.detector.calibration.drop_height_m = o.drop_height_m;
  dc.detector.time_scale = o.time_scale;
  dc.retiming.mode = FrameTimesMode(o.keep_frame_times);
  const ContainerClock container = is_file ? ReadContainerClock(clip) : ContainerClock{};
  dc.detector.capture_slowdown_hint = container.SlowDown();
  dc.detector.image_width_px = info.width;
  dc.detector.image_height_px = info.height;
  DetectNode detect(&bus, dc);

  FitInbox inbox;
  std::unique_ptr<FitNode> fit;
  int final_budget = 0;
  int final_sims_start = 0;  // simulations run when the final fit was asked for
  if (!o.no_fit) {
    const FitNodeConfig fc = FitConfig(o);
    fit = std::make_unique<FitNode>(
        fc, [&inbox](const fit_update_t& m, const FitUpdate& u) { inbox.Push(m, u); });
    fit->Start();
    final_budget = fit->final_budget();
  }

  if (info.nominal_fps > 0) sound.set_frame_period_s(1.0 / info.nominal_fps);
  console.Info("run: " + info.description + ", " + Fixed(info.nominal_fps, 2) + " fps; ball " +
               ball.name + " (" + Fixed(ball.diameter_m * 1e3, 1) + " mm, " +
               Fixed(ball.mass_kg * 1e3, 1) + " g); output " + out.dir().string() + "; bus " + o.lcm_url +
               "; sound: " + (o.no_audio ? "off (--no-audio)" : sound.Describe()));

  std::optional<FitUpdate> final_fit;
  int64_t now_utime = 0;  // capture time of the latest frame: the stream's "now"
  int64_t release_utime = 0;
  std::vector<bounce_peak_t> peaks;
  std::optional<calibration_t> calibration;
  ClockReport clock_report;
  auto handle_fit_updates = [&] {
    for (auto& [m, u] : inbox.Take()) {
      bus.Publish(o.channels.fit_update, m);
      out.Log(o.channels.fit_update, m);
      out.OnFit(m, now_utime);
      console.OnFit(m, now_utime);
      if (u.final && u.model == fit->model().name()) final_fit = u;
    }
  };
  // A bounce whose arc was heard from end to end goes out again with its flight-time height.
  auto publish_heard_peaks = [&] {
    for (const auto& m : sound.HeardPeaks(peaks, out.stream_start(), now_utime)) {
      bus.Publish(o.channels.bounce_peak, m);
      out.Log(o.channels.bounce_peak, m);
      console.OnPeak(m);
      if (fit) fit->OnPeak(m);
    }
  };
  auto handle_events = [&](const std::vector<DetectorEvent>& events) {
    for (const auto& e : events) {
      if (e.kind == DetectorEvent::Kind::kCalibration) {
        ReportClock(e.calibration, container, o.time_scale > 0, &clock_report, console);
        const calibration_t m = ToCalibrationMsg(e.calibration);
        out.Log(o.channels.calibration, m);
        out.OnCalibration(m);
        console.OnCalibration(m);
        calibration = m;
      } else if (e.kind == DetectorEvent::Kind::kPeak) {
        const bounce_peak_t m = ToBouncePeakMsg(e.peak);
        out.Log(o.channels.bounce_peak, m);
        out.OnPeak(m);
        console.OnPeak(m);
        if (m.bounce == 0) release_utime = m.apex_utime;
        peaks.push_back(m);
        if (fit) fit->OnPeak(m);
      } else if (e.kind == DetectorEvent::Kind::kImpact) {
        publish_impact(sound.Seen(SecondsSince(e.impact.utime, out.stream_start()), out.stream_start(),
                                  {e.impact.sequence, e.impact.index}));
        publish_heard_peaks();
      } else if (e.kind == DetectorEvent::Kind::kSequenceEnd) {
        const auto ended = detect.Summaries();
        console.Info("drop ended (" + e.reason + ")" + (ended.empty() ? "" : RefitHeights(ended.back())));
        // The refitted heights go out as BOUNCE_PEAK again (a fit node or a watcher on the
        // bus, the log), and the final fit takes them (a bounce heard end to end keeps its
        // flight-time height).
        if (!ended.empty())
          for (const bounce_peak_t& m : RefittedPeakMsgs(ended.back(), now_utime)) {
            if (sound.WasHeard(m.sequence, m.bounce)) continue;
            bus.Publish(o.channels.bounce_peak, m);
            out.Log(o.channels.bounce_peak, m);
            if (fit) fit->OnPeak(m);
          }
        if (fit) {
          fit->Finish();
          final_sims_start = fit->simulations();
          // The thorough fit takes seconds (docs/PERFORMANCE.md): say so before the silence.
          console.Info("final fit: up to " + std::to_string(final_budget) +
                       " simulations on all cores (seconds to a minute)");
        }
      }
    }
  };

  bool stream_started = false;
  capture.set_observer([&](const Frame& frame, const BallObservation& obs) {
    if (!stream_started) {
      stream_started = true;
      out.SetStreamStart(frame.utime);
      console.SetStreamStart(frame.utime);
    }
    now_utime = frame.utime;
    out.OnBox(ToBallBox(obs));
    const bool retiming_known = detect.retiming().decided;
    const auto events = detect.OnObservation(obs);
    if (!retiming_known && detect.retiming().retimed) console.Info("clock: " + detect.retiming().verdict);
    handle_events(events);
    const auto heard = sound.AdvanceTo(SecondsSince(frame.utime, out.stream_start()), out.stream_start());
    for (const auto& m : heard) publish_impact(m);
    if (!heard.empty()) publish_heard_peaks();
  });

  struct sigaction sa {};
  sa.sa_handler = OnRunSignal;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);

  const double total_s = info.frame_count > 0 && info.nominal_fps > 0
                             ? static_cast<double>(info.frame_count) / info.nominal_fps
                             : 0;
  std::string failure;
  try {
    while (!g_stop && capture.Step()) {
      handle_fit_updates();
      const auto& s = capture.stats();
      console.Progress(s.stream_s(), total_s, s.frames, s.found);
    }
  } catch (const std::exception& e) {
    failure = e.what();  // keep going: close the drop, fit, and write what we have
  }
  handle_events(detect.Finish());
  // A file cut short: say how much of it there was; with no apex found it gave nothing usable.
  const auto* file_source = dynamic_cast<const VideoFileSource*>(source.get());
  if (file_source && file_source->ended_short() && failure.empty()) {
    const std::string read = clip + " ended after " + std::to_string(capture.stats().frames) +
                             " of the " + std::to_string(info.frame_count) +
                             " frames it announces (truncated or damaged?)";
    if (peaks.empty())
      failure = read + "; nothing usable was read";
    else
      console.Info("run: warning: " + read);
  }
  // A whole file without the ball in any frame gave nothing to measure: say so, non-zero.
  if (file_source && failure.empty() && !g_stop && capture.stats().frames > 0 &&
      capture.stats().found == 0)
    failure = clip + ": no ball found in any of its " + std::to_string(capture.stats().frames) +
              " frames" +
              (o.tracker.has_color || o.tracker.has_chroma || o.tracker.has_pick || o.tracker.luma_mode
                   ? " (nothing of the colour or brightness given)"
                   : " (nothing moved like a ball and stood out of its surroundings; if it is "
                     "there, --color or --pick names it)");
  // The ball followed but no bounce found: the output has a track and nothing measured.
  if (file_source && failure.empty() && !g_stop && peaks.empty() && capture.stats().found > 0)
    console.Info("run: warning: " + clip + ": no bounce found (the ball, or what was taken for it, was seen in " +
                 std::to_string(capture.stats().found) + " of " + std::to_string(capture.stats().frames) +
                 " frames, never on an arc between two impacts above the floor; the tracker's choice "
                 "is below, and --color or --pick names the ball)");
  if (file_source && file_source->undecodable_frames() > 0)
    console.Info("run: warning: " + clip + ": " + std::to_string(file_source->undecodable_frames()) +
                 " frames could not be decoded (damaged data) and were skipped; the stream went "
                 "on after them, with a gap in the track");
  if (file_source && file_source->repeated_frames() > 0)
    console.Info("run: " + std::to_string(file_source->repeated_frames()) + " of " +
                 std::to_string(file_source->repeated_frames() + capture.stats().frames) +
                 " pictures repeat the one before (content of a lower frame rate on this file's "
                 "timeline): skipped, each picture tracked once at the time it was first shown");
  if (stream_started)
    for (const auto& m : sound.EndLive(out.stream_start())) publish_impact(m);
  publish_heard_peaks();
  const std::vector<SequenceSummary> summaries = detect.Summaries();  // every drop has ended
  std::vector<double> seen_impacts;
  for (const auto& d : summaries)
    for (const auto& i : d.impacts) seen_impacts.push_back(SecondsSince(i.utime, out.stream_start()));
  console.Info("sound: " + sound.Finish(seen_impacts, SecondsSince(now_utime, out.stream_start())).verdict);
  sound.WriteImpactsCsv(out.dir());
  sound.WriteWaveformCsv(out.dir());
  const std::vector<RunSound::AfterRefit> after_refit = AfterRefitOf(peaks, summaries);
  sound.RewritePeaksCsv(out.dir(), peaks, after_refit, out.stream_start());
  if (fit) {
    fit->Finish();
    while (!fit->WaitIdleFor(std::chrono::milliseconds(200)))
      console.FitProgress(fit->simulations() - final_sims_start, final_budget);
    handle_fit_updates();
    fit->Stop();
  }

  // What a user takes away: the final coefficients as JSON and as the fitted_ball project,
  // and the simulated trajectory for the report.
  if (final_fit && fit) {
    WriteFitExports(out.dir(), *final_fit, ball);
    WriteSimulatedTrajectory(out, *fit, *final_fit, release_utime);
  }
  const auto& cs = capture.stats();
  const auto [logged, log_dropped] = out.CloseLog();

  nlohmann::json summary;
  summary["input"] = is_file ? clip : o.device;
  summary["ball"] = {{"name", ball.name}, {"diameter_m", ball.diameter_m}, {"mass_kg", ball.mass_kg}};
  summary["frames"] = cs.frames;
  summary["found_frames"] = cs.found;
  summary["dropped_frames"] = cs.dropped;
  summary["repeated_frames"] = file_source ? file_source->repeated_frames() : 0;
  summary["duration_s"] = cs.stream_s();
  summary["wall_time_s"] = cs.wall_s;
  summary["timings_ms"] = {{"decode", cs.read_s * 1e3},
                           {"track", cs.track_s * 1e3},
                           {"detect", detect.stats().detect_s * 1e3},
                           {"sound", sound.cpu_s() * 1e3}};
  summary["sound"] = sound.Summary();
  summary["stopped_by_user"] = g_stop.load();
  if (!failure.empty()) summary["failure"] = failure;
  summary["log"] = {{"messages", logged}, {"dropped", log_dropped}};
  summary["calibration"] = calibration ? ToJson(*calibration, out.stream_start()) : nlohmann::json();
  summary["clock"] = {{"time_scale", detect.detector().time_scale()},
                      {"container_capture_fps", container.capture_fps},
                      {"container_stored_fps", container.stored_fps},
                      {"report", clock_report.text},
                      {"frame_times", detect.retiming().verdict}};
  // The rows are on the clock the pictures were taken on; track.csv keeps the stamps.
  const Retiming& retiming = detect.retiming();
  summary["clock"]["frames_retimed"] =
      retiming.applied ? nlohmann::json{{"source_fps", retiming.source_fps},
                                        {"phase", retiming.phase},
                                        {"first_frame_s", out.stream_start() * 1e-6}}
                       : nlohmann::json();
  nlohmann::json jpeaks = nlohmann::json::array();
  for (size_t i = 0; i < peaks.size(); ++i) {
    nlohmann::json jp = ToJson(peaks[i], out.stream_start());
    // The height refitted with every arc of its drop when the drop ended, beside the live one.
    jp["refit_height_m"] = FiniteOrNull(after_refit[i].refit_m);
    jpeaks.push_back(jp);
  }
  summary["peaks"] = jpeaks;
  nlohmann::json drops = nlohmann::json::array();
  for (const auto& d : summaries) {
    nlohmann::json impacts = nlohmann::json::array();
    for (const auto& i : d.impacts)
      impacts.push_back({{"bounce", i.index},
                         {"t_s", SecondsSince(i.utime, out.stream_start())},
                         {"speed_in_mps", i.speed_in_mps},
                         {"speed_out_mps", i.speed_out_mps},
                         {"restitution", i.restitution}});
    // Every arc refitted with all of them at the drop's end, beside its flight-time height
    // (bounce = first_bounce + index): what the live peaks became once the whole drop was seen.
    nlohmann::json final_h = nlohmann::json::array(), flight_h = nlohmann::json::array();
    for (double h : d.final_height_m) final_h.push_back(FiniteOrNull(h));
    for (double h : d.flight_height_m) flight_h.push_back(FiniteOrNull(h));
    drops.push_back({{"sequence", d.sequence},
                     {"end", d.end_reason},
                     {"first_bounce", d.first_bounce},
                     {"final_height_m", final_h},
                     {"flight_height_m", flight_h},
                     {"impacts", impacts},
                     {"restitution_intercept", FiniteOrNull(d.restitution_intercept)},
                     {"restitution_slope_per_mps", FiniteOrNull(d.restitution_slope_per_mps)}});
  }
  summary["drops"] = drops;
  if (final_fit) summary["final_fit"] = FitUpdateToJson(*final_fit, ball);
  if (fit) {
    const auto fs = fit->stats();
    summary["fit_stats"] = {{"peaks", fs.peaks},
                            {"updates", fs.updates_delivered},
                            {"superseded", fs.superseded},
                            {"finals", fs.finals}};
  }
  out.WriteSummary(summary);

  std::string human = "run: " + std::string(g_stop ? "stopped" : failure.empty() ? "done" : "failed") +
                      ": " + std::to_string(cs.frames) + " frames (" + Fixed(cs.stream_s(), 2) +
                      " s of stream in " + Fixed(cs.wall_s, 2) + " s), ball in " +
                      std::to_string(cs.found) + ", " + std::to_string(cs.dropped) +
                      " dropped; " + std::to_string(peaks.size()) + " peaks";
  if (final_fit) human += "; final fit residual " + Fixed(final_fit->residual_m * 1e3, 1) + " mm";
  human += "; wrote " + out.dir().string() + "\n" + tracker.Describe();
  console.Summary(human, nlohmann::json{{"event", "summary"}, {"summary", summary}}.dump());
  if (!failure.empty()) throw std::runtime_error(failure + " (what was recorded is in " +
                                                 out.dir().string() + ")");
}

void AddRunCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "run",
      "Everything in one process: replay a clip (or the built-in sample) at its recorded pace, "
      "track, calibrate, detect every bounce apex and fit the ball model after each bounce");
  auto o = std::make_shared<RunOptions>();
  auto* clip = cmd->add_option("clip", o->clips,
                               "clip to replay (.avi/.mp4/.mov); none: the built-in sample drop; "
                               "several: drops of one ball, each run into OUT/<k>-<name>/, fitted jointly")
                   ->check(CLI::ExistingFile);
  cmd->add_option("--device", o->device, "a V4L2 camera instead of a clip, e.g. /dev/video0")
      ->excludes(clip);
  cmd->add_option("--out", o->out, "output directory (docs/FORMATS.md)")->capture_default_str();
  cmd->add_option("--ball", o->ball, "ball preset: " + BallPresetNames() +
                                         " (default: the sample's, else pingpong)");
  cmd->add_option("--diameter", o->diameter_m, "ball diameter, m (overrides the preset)")
      ->check(Positive());
  cmd->add_option("--mass", o->mass_kg, "ball mass, kg (overrides the preset)")
      ->check(Positive());
  cmd->add_option("--speed", o->speed, "replay at this multiple of real time (0: as fast as possible)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("--quiet,-q", o->quiet, "print nothing but errors");
  cmd->add_flag("--json", o->json, "print one JSON object per event (calibration, peak, fit, summary)");
  cmd->add_flag("--no-fit", o->no_fit, "track and detect only");
  auto* no_audio =
      cmd->add_flag("--no-audio", o->no_audio, "ignore the clip's sound track (impacts from the picture only)");
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
  cmd->add_option("--max-evals", o->max_evals, "simulations for the final fit (0: default)")
      ->check(NonNegative());
  cmd->add_option("--px-per-m", o->px_per_m, "image scale, px/m (default: from free fall)")
      ->check(Positive());
  cmd->add_option("--drop-height", o->drop_height_m,
                  "release height of the ball bottom, m (sets the scale)")
      ->check(Positive());
  cmd->add_option("--time-scale", o->time_scale,
                  "real seconds per second of the file's timeline (0.25: a 4x slow-motion "
                  "file; default: as recorded unless the container's capture rate and the "
                  "ball's size agree it is slowed, or the free fall is 16x or 64x weaker than "
                  "the size says: 4x or 8x slow motion that no wrong ball size explains)")
      ->check(NonNegative());
  AddFrameTimesFlags(cmd, &o->retime_frames, &o->keep_frame_times);
  cmd->add_option("--max-frames", o->max_frames, "stop after this many frames (0: no limit)")
      ->check(NonNegative());
  AddBusFlags(cmd, &o->lcm_url, &o->channels);
  AddTrackerFlags(cmd, &o->tracker, &o->pick_window);
  cmd->callback([o] { o->clips.size() > 1 ? RunSeveral(*o) : RunOneClip(*o); });
}

}  // namespace bouncefit::cli
