// bouncefit capture: a V4L2 camera, or a clip replayed as a fake camera, through the tracker;
// one ball_box_t per frame on BALL_BOX (pipeline/capture_stage.h). Beside it, the sound: the
// clip's own track, or a live ALSA microphone beside the camera; each impact heard goes out
// on IMPACT (source "audio") as the stream reaches it.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <vector>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "capture/v4l2_camera.h"
#include "capture/v4l2_device_query.h"
#include "cli/bus_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "cli/output_flags.h"
#include "cli/pick_window.h"
#include "cli/stop_signal.h"
#include "cli/tracker_flags.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"
#include "pipeline/capture_stage.h"
#include "pipeline/exit_status.h"
#include "pipeline/output_dir.h"
#include "replay/video_file_source.h"

namespace bouncefit::cli {
namespace {

struct CaptureOptions {
  std::string replay;
  std::string device;
  bool list_devices = false;
  bool list_formats = false;
  double fps = 120;
  std::string size = "640x480";
  std::string pixel_format = "auto";
  int buffers = 4;
  double speed = 1.0;
  bool loop = false;
  std::string record;
  std::string log;
  std::string out;
  bool overwrite = false;
  std::string lcm_url = kDefaultLcmUrl;
  Channels channels;
  int64_t max_frames = 0;
  bool quiet = false;
  TrackerConfig tracker;
  bool pick_window = false;
  bool no_audio = false;
  std::string audio_device;  // ALSA microphone beside --device
};

void ParseSize(const std::string& text, int* w, int* h) {
  char x = 0;
  std::istringstream in(text);
  if (!(in >> *w >> x >> *h) || (x != 'x' && x != 'X') || !(in >> std::ws).eof() || *w <= 0 ||
      *h <= 0)
    throw std::invalid_argument("--size must be WIDTHxHEIGHT in pixels, got '" + text + "'");
}

void ListDevices() {
  const auto devices = ListV4l2Devices();
  if (devices.empty()) {
    std::printf("no V4L2 capture device (/dev/video*) on this machine\n");
    return;
  }
  for (const auto& d : devices)
    std::printf("%s  %s  [%s, %s]\n", d.path.c_str(), d.card.c_str(), d.driver.c_str(),
                d.bus_info.c_str());
}

void ListFormats(const std::string& device) {
  for (const auto& f : ListV4l2Formats(device)) {
    std::printf("%s  %s%s\n", FourccToString(f.fourcc).c_str(), f.description.c_str(),
                f.compressed ? " (compressed)" : "");
    for (const auto& s : f.sizes) {
      std::string rates;
      for (const auto& i : s.intervals) rates += fmt::format("{}{:.2f}", rates.empty() ? "" : ", ", i.fps());
      if (s.interval_range) rates = "any from " + rates;
      std::printf("  %dx%d%s  fps: %s\n", s.width, s.height, f.size_range ? " (range end)" : "",
                  rates.empty() ? "?" : rates.c_str());
    }
  }
}

void Run(CaptureOptions& o) {
  if (o.list_devices) {
    ListDevices();
    return;
  }
  if (o.list_formats) {
    ListFormats(o.device.empty() ? "/dev/video0" : o.device);
    return;
  }
  if (o.replay.empty() == o.device.empty())
    throw std::invalid_argument("give exactly one of --replay CLIP or --device /dev/videoN");
  if (o.pick_window) CheckPickWindowDisplay();  // at once, before the camera or any file is opened

  CaptureStageConfig c;
  c.clip = o.replay;
  c.camera.device = o.device;
  if (!o.device.empty()) {
    ParseSize(o.size, &c.camera.width, &c.camera.height);
    c.camera.fps = o.fps;
    c.camera.pixel_format = o.pixel_format;
    c.camera.buffers = o.buffers;
  }
  c.loop = o.loop;
  c.speed = o.speed;
  c.max_frames = o.max_frames;
  c.no_audio = o.no_audio;
  c.audio_device = o.audio_device;
  c.record = o.record;
  c.tracker = o.tracker;
  c.channels = o.channels;
  c.log_path = o.log;
  if (o.pick_window) {
    const std::string picked = PickOnFirstFrame(
        [&]() -> std::unique_ptr<FrameSource> {
          if (o.replay.empty()) return std::make_unique<V4l2Camera>(c.camera);
          return std::make_unique<VideoFileSource>(VideoFileSourceConfig{o.replay, false});
        },
        &c.tracker);
    if (!o.quiet) std::printf("capture: %s\n", picked.c_str());
  }
  if (!o.out.empty()) {
    ClaimOutputDir(o.out, CaptureOutputFiles(), o.overwrite);
    c.out_dir = o.out;
  }
  LcmBus bus(o.lcm_url);
  CaptureStage stage(c, bus, [](const std::string& s) { std::printf("%s\n", s.c_str()); });
  const stream_t& st = stage.stream();
  if (!o.quiet) {
    fmt::print("capture: {}, {:.2f} fps nominal{}; publishing {} on {}{}; sound: {}\n", st.description, st.nominal_fps,
               st.is_file ? (o.speed > 0 ? fmt::format(", paced at speed {:.2f}", o.speed) : ", as fast as possible") : "",
               o.channels.ball_box, o.lcm_url, o.loop ? " (looping)" : "", st.sound);
    std::fflush(stdout);
  }

  const std::atomic<bool>& stop = StopOnSignal();

  auto last = std::chrono::steady_clock::now();
  while (!stop && stage.Step()) {
    if (!o.quiet && std::chrono::steady_clock::now() - last > std::chrono::seconds(1)) {
      last = std::chrono::steady_clock::now();
      fmt::print("capture: so far {} frames ({:.1f} s of stream), {} found\n", stage.frames(), stage.stream_s(),
                 stage.found());
      std::fflush(stdout);
    }
  }
  stage.End(stop);
  const stream_t& s = stage.end_message();
  fmt::print("capture: {}{} frames, {} dropped, {} found, {} published, wall {:.3f} s, stream {:.3f} s (read {:.2f} s, "
             "track {:.2f} s){}{}\n",
             stop ? "stopped: " : (s.failure.empty() ? "done: " : "failed after "), s.frames, s.dropped, s.found,
             s.frames - bus.publish_failures(), s.wall_s,
             s.frames > 0 ? (s.utime - stage.stream().utime) * 1e-6 : 0.0, s.read_s, s.track_s,
             o.out.empty() ? "" : "; wrote " + o.out,
             bus.publish_failures() ? fmt::format("; {} publish failures", bus.publish_failures()) : "");
  std::fflush(stdout);
  if (!s.failure.empty()) throw std::runtime_error(s.failure);
  if (stop) throw CLI::RuntimeError(kExitInterrupted);
}

}  // namespace

void AddCaptureCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "capture",
      "Read a camera (V4L2) or replay a clip as a fake camera; track the ball and publish "
      "BALL_BOX");
  auto o = std::make_shared<CaptureOptions>();
  auto* replay = cmd->add_option("--replay", o->replay, "replay this clip (.avi/.mp4/.mov) as a fake camera");
  auto* device = cmd->add_option("--device", o->device, "V4L2 camera, e.g. /dev/video0");
  replay->excludes(device);
  cmd->add_flag("--list-devices", o->list_devices, "list V4L2 capture devices and exit");
  cmd->add_flag("--list-formats", o->list_formats,
                "list the formats, sizes and frame rates of --device (default /dev/video0) and exit");
  cmd->add_option("--fps", o->fps, "camera: frame rate to ask for (0: the driver's current)")
      ->capture_default_str();
  cmd->add_option("--size", o->size, "camera: frame size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("--pixel-format", o->pixel_format,
                  "camera: auto (YUYV if it reaches --fps, else MJPEG), yuyv or mjpeg")
      ->check(CLI::IsMember({"auto", "yuyv", "mjpeg"}))
      ->capture_default_str();
  cmd->add_option("--buffers", o->buffers, "camera: mmap buffers")
      ->check(CLI::Range(2, 32))
      ->capture_default_str();
  cmd->add_option("--speed", o->speed, "replay: pace at this multiple of real time (0: as fast as possible)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("--loop", o->loop, "replay: start the clip again at its end");
  cmd->add_option("--record", o->record, "camera: save the frames to this .avi (and its .times.csv)");
  cmd->add_option("--log", o->log, "record every message it sends to this LCM log (.lcm; --out: OUT/session.lcm)");
  AddOutputFlags(cmd, &o->out, &o->overwrite, "track.csv, session.lcm and waveform.csv");
  AddBusFlags(cmd, &o->lcm_url, &o->channels);
  cmd->add_option("--max-frames", o->max_frames, "stop after this many frames (0: no limit)")
      ->check(NonNegative());
  cmd->add_flag("--quiet,-q", o->quiet, "print only the final line");
  AddTrackerFlags(cmd, &o->tracker, &o->pick_window);
  auto* no_audio = cmd->add_flag("--no-audio", o->no_audio, "replay: ignore the clip's sound track");
  cmd->add_option("--audio-device", o->audio_device,
                  "camera: ALSA microphone beside it (e.g. hw:1,0); impacts heard go out on IMPACT")
      ->excludes(no_audio);
  cmd->footer(
      "Examples:\n"
      "  bouncefit capture --replay drop.avi --out out/drop              # a clip as the camera\n"
      "  bouncefit capture --device /dev/video0 --fps 120 --record drop.avi   # keep a live drop");
  cmd->callback([o] { Run(*o); });
}

}  // namespace bouncefit::cli
