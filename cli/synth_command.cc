// bouncefit synth: render a ball-drop clip with known ground truth (synth/synth_clip.h).
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/number_checks.h"
#include "model/ball_preset.h"
#include "synth/synth_clip.h"

namespace bouncefit::cli {
namespace {

struct SynthOptions {
  SynthClipConfig clip;
  std::string ball = "pingpong";
  double diameter_m = 0, mass_kg = 0;
  double restitution = -1, restitution_per_mps = -1;  // < 0: the preset's
  std::string size = "640x480";
  std::string color, wall_color, floor_color;
  std::string wall_pattern = "plain";
  std::string floor_pattern = "plain";
  bool no_drag = false;
  bool quiet = false;
  std::string out = "synth.avi";
  bool sound = false;
  SynthAudioConfig audio;
};

Bgr ParseColor(const std::string& text, const char* what) {
  Bgr c{};
  char comma1 = 0, comma2 = 0;
  std::istringstream in(text);
  if (!(in >> c[0] >> comma1 >> c[1] >> comma2 >> c[2]) || comma1 != ',' || comma2 != ',' ||
      !(in >> std::ws).eof())
    throw std::invalid_argument(std::string(what) + " must be B,G,R (0-255 each), got '" + text +
                                "'");
  for (double v : c)
    if (v < 0 || v > 255)
      throw std::invalid_argument(std::string(what) + " channels must be in 0-255, got '" +
                                  text + "'");
  return c;
}

void ParseSize(const std::string& text, int* w, int* h) {
  char x = 0;
  std::istringstream in(text);
  if (!(in >> *w >> x >> *h) || (x != 'x' && x != 'X') || !(in >> std::ws).eof())
    throw std::invalid_argument("--size must be WxH in pixels, got '" + text + "'");
}

std::string Fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

void Run(SynthOptions o) {
  o.clip.ball = ResolveBallPreset(o.ball, o.diameter_m, o.mass_kg);
  if (o.diameter_m < 0) throw std::invalid_argument("--diameter must be > 0 m");
  if (o.mass_kg < 0) throw std::invalid_argument("--mass must be > 0 kg");
  if (o.restitution > 1) throw std::invalid_argument("--restitution must be in 0-1");
  if (o.restitution >= 0) o.clip.ball.restitution = o.restitution;
  if (o.restitution_per_mps >= 0) o.clip.ball.restitution_per_mps = o.restitution_per_mps;
  ParseSize(o.size, &o.clip.width, &o.clip.height);
  if (!o.color.empty()) o.clip.ball_bgr = ParseColor(o.color, "--color");
  if (!o.wall_color.empty()) o.clip.wall_bgr = ParseColor(o.wall_color, "--wall-color");
  o.clip.wall_pattern = ParseWallPattern(o.wall_pattern);
  if (!o.floor_color.empty()) o.clip.floor_bgr = ParseColor(o.floor_color, "--floor-color");
  o.clip.floor_pattern = ParseFloorPattern(o.floor_pattern);
  o.clip.drag = !o.no_drag;
  o.clip.out = o.out;
  if (o.sound || o.audio.chatter || o.audio.hum || o.audio.offset_s != 0) {
    o.audio.seed = o.clip.seed;
    o.clip.sound = o.audio;
  }

  const double fps = o.clip.fps;
  const bool quiet = o.quiet;
  const SynthClipResult r = RenderSynthClip(o.clip, [&](int done, int total) {
    if (quiet) return;
    const int per_second = std::max(1, static_cast<int>(std::lround(fps)));
    if (done % per_second == 0 || done == total)
      std::printf("synth: %s s of %s s rendered (%d/%d frames)\n", Fixed(done / fps, 1).c_str(),
                  Fixed(total / fps, 1).c_str(), done, total), std::fflush(stdout);
  });
  std::string apexes;
  for (double h : r.truth.apex_heights_m) apexes += (apexes.empty() ? "" : " ") + Fixed(h, 3);
  std::printf(
      "synth: wrote %s and %s: %d frames %dx%d at %g fps in %s s (cpu %s s: draw %s, noise %s, "
      "encode %s); apex heights (m): %s\n",
      r.clip_path.string().c_str(), r.truth_path.filename().string().c_str(),
      r.truth.frame_count, r.truth.width, r.truth.height, r.truth.fps,
      Fixed(r.render_wall_s, 2).c_str(), Fixed(r.render_cpu_s, 2).c_str(),
      Fixed(r.scene_s, 2).c_str(),
      Fixed(r.noise_s, 2).c_str(), Fixed(r.encode_s, 2).c_str(), apexes.c_str());
}

}  // namespace

void AddSynthCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "synth",
      "Render a ball-drop clip with known ground truth: a point mass with air drag and "
      "restitution, a static camera on a wall and floor. Writes the clip and, next to it, "
      "<clip>.truth.json (docs/FORMATS.md).");
  auto o = std::make_shared<SynthOptions>();
  SynthClipConfig& c = o->clip;
  cmd->add_option("--out,-o", o->out, "Output clip: .avi (MJPEG) or .mp4 (needs FFmpeg)")
      ->capture_default_str();
  cmd->add_option("--ball", o->ball, "Ball preset: " + BallPresetNames())->capture_default_str();
  cmd->add_option("--diameter", o->diameter_m, "Override the preset's diameter, metres");
  cmd->add_option("--mass", o->mass_kg, "Override the preset's mass, kilograms");
  cmd->add_option("--drop-height", c.drop_height_m,
                  "Ball bottom above the floor at release, metres")
      ->capture_default_str();
  cmd->add_option("--hold", c.hold_s, "Ball held still before release, seconds")
      ->capture_default_str();
  cmd->add_option("--throw-up", c.launch_up_mps,
                  "Vertical speed at release, m/s, up positive (0: dropped from rest)")
      ->capture_default_str();
  cmd->add_option("--throw-right", c.launch_right_mps,
                  "Horizontal speed at release, m/s, right positive (drag-free)")
      ->capture_default_str();
  cmd->add_option("--start-after-release", c.start_after_release_s,
                  "Start the clip this long after the release, s (mid-bounce; no hold shown)")
      ->capture_default_str();
  cmd->add_option("--g", c.g_mps2, "Gravitational acceleration, m/s^2")->capture_default_str();
  cmd->add_flag("--no-drag", o->no_drag, "Switch air drag off (vacuum)");
  cmd->add_option("--restitution", o->restitution,
                  "Restitution at impact speed 0, e0 in e(v) = e0 - k v (default: the preset's)")
      ->check(NonNegative());
  cmd->add_option("--restitution-per-mps", o->restitution_per_mps,
                  "Restitution lost per m/s of impact speed, k in e(v) = e0 - k v, 1/(m/s) "
                  "(default: the preset's)")
      ->check(NonNegative());
  cmd->add_option("--fps", c.fps, "Frame rate, frames per second")->capture_default_str();
  cmd->add_option("--size", o->size, "Frame size WxH, pixels")->capture_default_str();
  cmd->add_option("--duration", c.duration_s, "Clip length, seconds")->capture_default_str();
  cmd->add_option("--px-per-m", c.px_per_m,
                  "Image scale, pixels per metre (0 = fit the drop into the frame)")
      ->capture_default_str();
  cmd->add_option("--ball-x", c.ball_x,
                  "Horizontal ball position, fraction of the width (0 = left, 1 = right)")
      ->capture_default_str();
  cmd->add_option("--roll", c.roll_deg,
                  "Camera roll, degrees: the scene turns counter-clockwise on screen")
      ->capture_default_str();
  cmd->add_option("--camera-jitter", c.camera_jitter_px,
                  "A camera held in a hand: each frame moved by up to this much each way, px")
      ->capture_default_str();
  cmd->add_option("--camera-sway", c.camera_sway_px,
                  "A camera held in a hand: a slow sway (0.7 Hz) of this amplitude, px")
      ->capture_default_str();
  cmd->add_option("--exposure", c.exposure_s,
                  "Exposure time for motion blur, seconds (0 = no blur, at most 1/fps)")
      ->capture_default_str();
  cmd->add_option("--blur-samples", c.blur_samples,
                  "Sub-exposures averaged per frame (0 = enough for 0.5 px steps)")
      ->capture_default_str();
  cmd->add_option("--noise", c.noise_sigma, "Gaussian sensor noise sigma, grey levels (0-255)")
      ->capture_default_str();
  cmd->add_option("--seed", c.seed, "Random seed of the noise (same seed, same clip)")
      ->capture_default_str();
  cmd->add_option("--color", o->color, "Ball colour B,G,R, 0-255 each (default: the preset's)");
  cmd->add_option("--wall-color", o->wall_color, "Wall colour B,G,R, 0-255 each (default 196,202,206)");
  cmd->add_option("--wall-pattern", o->wall_pattern,
                  "Wall surface: plain, brick (bricks of the wall colour) or poster (patches of every hue)")
      ->capture_default_str();
  cmd->add_option("--floor-color", o->floor_color,
                  "Floor colour B,G,R, 0-255 each (default 112,118,124)");
  cmd->add_option("--floor-pattern", o->floor_pattern,
                  "Floor surface: plain (the floor colour) or pebble (tiles of many greys and "
                  "browns, each about a ball's diameter across, px from the scale)")
      ->capture_default_str();
  cmd->add_flag("--distractor", c.distractor,
                "Add a static sphere of similar hue resting on the floor");
  cmd->add_option("--quality", c.quality, "MJPEG quality, 1-100")->capture_default_str();
  cmd->add_flag("--sound", o->sound,
                "Add a sound track: a click at each impact (louder for faster ones) over room "
                "noise (.avi only)");
  cmd->add_option("--sound-offset", o->audio.offset_s,
                  "The sound lags the picture by this, seconds (negative: leads; implies --sound)")
      ->capture_default_str();
  cmd->add_flag("--chatter", o->audio.chatter, "Voices in the room's sound (implies --sound)");
  cmd->add_flag("--hum", o->audio.hum, "Mains hum in the sound, 50 Hz and harmonics (implies --sound)");
  cmd->add_option("--sound-rate", o->audio.sample_rate, "Sound sample rate, Hz")
      ->capture_default_str();
  cmd->add_option("--room-noise", o->audio.noise_rms, "Room noise RMS, full scale 1")
      ->capture_default_str();
  cmd->add_flag("--quiet,-q", o->quiet, "Print only the final summary line");
  cmd->footer("Example:\n  bouncefit synth --ball softball --drop-height 1.6 --roll 1 --out soft.avi");
  cmd->callback([o] { Run(*o); });
}

}  // namespace bouncefit::cli
