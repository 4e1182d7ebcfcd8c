// bouncefit capture: a V4L2 camera, or a clip replayed as a fake camera, through the tracker;
// one ball_box_t per frame on BALL_BOX (track/node/capture_node.h). Beside it, the sound: the
// clip's own track, or a live ALSA microphone beside the camera; each impact heard goes out
// on IMPACT (source "audio") as the stream reaches it (cli/run_sound.h).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <vector>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "capture/frame_recorder.h"
#include "capture/v4l2_camera.h"
#include "cli/bus_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "cli/pick_window.h"
#include "cli/run_sound.h"
#include "cli/tracker_flags.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"
#include "msgs/lcm_log_recorder.h"
#include "replay/pacer.h"
#include "replay/video_file_source.h"
#include "track/node/capture_node.h"

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
  std::string lcm_url = kDefaultLcmUrl;
  Channels channels;
  int64_t max_frames = 0;
  bool quiet = false;
  TrackerConfig tracker;
  bool pick_window = false;
  bool no_audio = false;
  std::string audio_device;  // ALSA microphone beside --device
};

std::atomic<bool> g_stop{false};
extern "C" void OnSignal(int) { g_stop = true; }

std::string Fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

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
      for (const auto& i : s.intervals) rates += (rates.empty() ? "" : ", ") + Fixed(i.fps(), 2);
      if (s.interval_range) rates = "any from " + rates;
      std::printf("  %dx%d%s  fps: %s\n", s.width, s.height, f.size_range ? " (range end)" : "",
                  rates.empty() ? "?" : rates.c_str());
    }
  }
}

void PrintProgress(const CaptureStats& s, const std::string& what) {
  std::printf("capture: %s %lld frames (%s s of stream), %lld found, %lld dropped, %s fps\n",
              what.c_str(), static_cast<long long>(s.frames), Fixed(s.stream_s(), 1).c_str(),
              static_cast<long long>(s.found), static_cast<long long>(s.dropped),
              Fixed(s.wall_s > 0 ? s.frames / s.wall_s : 0, 1).c_str());
  std::fflush(stdout);
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
  if (!o.replay.empty() && !o.record.empty())
    throw std::invalid_argument("--record saves a camera; a replayed clip is already a file");
  if (!o.audio_device.empty() && o.device.empty())
    throw std::invalid_argument("--audio-device needs --device (a replayed clip's own sound track is used)");
  Pacer pacer(o.speed);  // validates --speed
  if (o.pick_window) CheckPickWindowDisplay();  // at once, before the camera or any file is opened

  auto open_camera = [&o] {
    V4l2CameraConfig c;
    c.device = o.device;
    ParseSize(o.size, &c.width, &c.height);
    c.fps = o.fps;
    c.pixel_format = o.pixel_format;
    c.buffers = o.buffers;
    return std::make_unique<V4l2Camera>(c);
  };
  if (o.pick_window) {
    const std::string picked = PickOnFirstFrame(
        [&]() -> std::unique_ptr<FrameSource> {
          if (o.replay.empty()) return open_camera();
          return std::make_unique<VideoFileSource>(VideoFileSourceConfig{o.replay, false});
        },
        &o.tracker);
    if (!o.quiet) std::printf("capture: %s\n", picked.c_str());
  }
  std::unique_ptr<FrameSource> source;
  bool is_file = false;
  VideoFileSource* file = nullptr;
  if (!o.replay.empty()) {
    auto f = std::make_unique<VideoFileSource>(VideoFileSourceConfig{o.replay, o.loop});
    file = f.get();
    source = std::move(f);
    is_file = true;
  } else {
    source = open_camera();
  }
  const SourceInfo info = source->Info();
  Tracker tracker(o.tracker);
  LcmBus bus(o.lcm_url);
  std::unique_ptr<LcmLogRecorder> log;
  if (!o.log.empty()) log = std::make_unique<LcmLogRecorder>(o.log);
  std::unique_ptr<FrameRecorder> recorder;
  if (!o.record.empty()) recorder = std::make_unique<FrameRecorder>(o.record, info.nominal_fps);

  CaptureNodeConfig nc;
  nc.channels = o.channels;
  nc.max_frames = o.max_frames;
  CaptureNode node(*source, tracker, &bus, nc);
  if (is_file && o.speed > 0) node.set_pacer([&pacer](int64_t t) { return pacer.WaitFor(t); });
  if (log) node.set_log(log.get());
  if (recorder) node.set_recorder(recorder.get());

  // The sound: heard impacts published on IMPACT as the frames reach their time. The ball
  // only matters to fusing (which `run` and `detect` do), not to hearing.
  std::unique_ptr<RunSound> sound;
  if (!o.audio_device.empty())
    sound = std::make_unique<RunSound>(AlsaMicrophoneConfig{.device = o.audio_device, .config_text = {}}, BallPreset{});
  else if (is_file && !o.no_audio)
    sound = std::make_unique<RunSound>(o.replay, BallPreset{});
  if (sound && !sound->enabled()) sound.reset();
  int64_t heard = 0, t0_utime = -1;
  std::vector<uint8_t> impact_bytes;
  const auto publish_impact = [&](const impact_t& m) {
    bus.Publish(o.channels.impact, m);
    ++heard;
    if (!log) return;
    impact_bytes.resize(static_cast<size_t>(m.getEncodedSize()));
    m.encode(impact_bytes.data(), 0, static_cast<int>(impact_bytes.size()));
    const auto now = std::chrono::duration_cast<std::chrono::microseconds>(
        std::chrono::system_clock::now().time_since_epoch());
    log->Record(o.channels.impact, impact_bytes.data(), impact_bytes.size(), now.count());
  };
  if (sound)
    node.set_observer([&](const Frame& frame, const BallObservation&) {
      if (t0_utime < 0) t0_utime = frame.utime;
      for (const auto& m : sound->AdvanceTo((frame.utime - t0_utime) * 1e-6, t0_utime)) publish_impact(m);
    });

  if (!o.quiet) {
    std::printf("capture: %s, %s fps nominal%s; publishing %s on %s%s\n",
                info.description.c_str(), Fixed(info.nominal_fps, 2).c_str(),
                is_file ? (o.speed > 0 ? ", paced at speed " + Fixed(o.speed, 2) : std::string(", as fast as possible")).c_str() : "",
                o.channels.ball_box.c_str(), o.lcm_url.c_str(),
                o.loop ? " (looping)" : "");
    std::fflush(stdout);
  }

  struct sigaction sa {};
  sa.sa_handler = OnSignal;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);

  std::string failure;
  try {
    node.Run(&g_stop, o.quiet ? std::function<void(const CaptureStats&)>()
                              : [](const CaptureStats& s) { PrintProgress(s, "so far"); });
  } catch (const std::exception& e) {
    failure = e.what();
  }
  // The impacts still pending: the rest of the clip's sound, or what the microphone holds.
  if (sound && t0_utime >= 0) {
    try {
      const double end_s = (node.stats().last_utime - t0_utime) * 1e-6 +
                           (info.nominal_fps > 0 ? 1 / info.nominal_fps : 0);
      for (const auto& m : o.audio_device.empty() ? sound->AdvanceTo(end_s, t0_utime)
                                                   : sound->EndLive(t0_utime))
        publish_impact(m);
    } catch (const std::exception& e) {
      if (failure.empty()) failure = e.what();
    }
  }
  // Whatever happened, keep what was captured: finish the recording and the log.
  if (recorder) recorder->Close();
  if (log) log->Close();
  const CaptureStats& s = node.stats();
  if (file && file->undecodable_frames() > 0)
    std::printf("capture: warning: %s: %lld frames could not be decoded (damaged data) and "
                "were skipped\n",
                o.replay.c_str(), static_cast<long long>(file->undecodable_frames()));
  if (file && file->ended_short())
    std::printf("capture: warning: %s ended after %lld of the %lld frames it announces "
                "(truncated or damaged?)\n",
                o.replay.c_str(), static_cast<long long>(s.frames),
                static_cast<long long>(info.frame_count));
  std::printf(
      "capture: %s%lld frames, %lld dropped, %lld found, %lld published, wall %s s, stream %s "
      "s (read %s s, track %s s)%s%s%s%s\n",
      g_stop ? "stopped: " : (failure.empty() ? "done: " : "failed after "),
      static_cast<long long>(s.frames), static_cast<long long>(s.dropped),
      static_cast<long long>(s.found), static_cast<long long>(s.published),
      Fixed(s.wall_s, 3).c_str(), Fixed(s.stream_s(), 3).c_str(), Fixed(s.read_s, 2).c_str(),
      Fixed(s.track_s, 2).c_str(),
      recorder ? ("; recorded " + std::to_string(recorder->written()) + " frames to " + o.record).c_str() : "",
      log ? ("; logged " + std::to_string(log->written()) + " messages to " + o.log).c_str() : "",
      s.publish_failures ? ("; " + std::to_string(s.publish_failures) + " publish failures").c_str() : "",
      sound ? ("; sound: " + sound->Describe() + ", " + std::to_string(heard) + " impacts heard on " +
               o.channels.impact).c_str()
            : "");
  std::fflush(stdout);
  if (!failure.empty()) throw std::runtime_error(failure);
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
  cmd->add_option("--log", o->log, "record every published message to this LCM log (.lcm)");
  AddBusFlags(cmd, &o->lcm_url, &o->channels);
  cmd->add_option("--max-frames", o->max_frames, "stop after this many frames (0: no limit)")
      ->check(NonNegative());
  cmd->add_flag("--quiet,-q", o->quiet, "print only the final line");
  AddTrackerFlags(cmd, &o->tracker, &o->pick_window);
  auto* no_audio = cmd->add_flag("--no-audio", o->no_audio, "replay: ignore the clip's sound track");
  cmd->add_option("--audio-device", o->audio_device,
                  "camera: ALSA microphone beside it (e.g. hw:1,0); impacts heard go out on IMPACT")
      ->excludes(no_audio);
  cmd->callback([o] { Run(*o); });
}

}  // namespace bouncefit::cli
