// bouncefit synth: render a ball-drop clip with known ground truth (synth/synth_clip.h).
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "cli/ball_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "model/ball_preset.h"
#include "synth/synth_clip.h"

namespace bouncefit::cli {
namespace {

struct SynthOptions {
  SynthClipConfig clip;
  BallFlags ball;
  double restitution = -1, restitution_per_mps = -1;  // < 0: the preset's
  std::string size = "640x480";
  std::string color, wall_color, floor_color, seam_color;
  std::string seams = "none";
  std::string wall_pattern = "plain";
  std::string floor_pattern = "plain";
  bool no_drag = false;
  bool quiet = false;
  std::string out = "synth.avi";
  bool sound = false;
  SynthAudioConfig audio;
  int drops = 0;
};

// Several drops with no distances given: towards and away from the camera in turn, m.
std::vector<double> DefaultDropDistances(int drops) {
  const double pattern[] = {1.6, 2.6, 1.1, 2.1, 1.3};
  std::vector<double> d;
  for (int k = 0; k < drops; ++k) d.push_back(pattern[k % 5]);
  return d;
}

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

void Run(SynthOptions o) {
  o.clip.ball = ResolveBall(o.ball);
  if (o.restitution > 1) throw std::invalid_argument("--restitution must be in 0-1");
  if (o.restitution >= 0) o.clip.ball.restitution = o.restitution;
  if (o.restitution_per_mps >= 0) o.clip.ball.restitution_per_mps = o.restitution_per_mps;
  ParseSize(o.size, &o.clip.width, &o.clip.height);
  if (!o.color.empty()) o.clip.ball_bgr = ParseColor(o.color, "--color");
  if (!o.wall_color.empty()) o.clip.wall_bgr = ParseColor(o.wall_color, "--wall-color");
  o.clip.wall_pattern = ParseWallPattern(o.wall_pattern);
  if (!o.floor_color.empty()) o.clip.floor_bgr = ParseColor(o.floor_color, "--floor-color");
  o.clip.floor_pattern = ParseFloorPattern(o.floor_pattern);
  o.clip.seams = ParseSeamPattern(o.seams);
  if (!o.seam_color.empty()) o.clip.seam_bgr = ParseColor(o.seam_color, "--seam-color");
  o.clip.drag = !o.no_drag;
  if (o.drops < 0 || o.drops > 20) throw std::invalid_argument("--drops must be in 0-20");
  if (o.drops > 0 && o.clip.drop_distances_m.empty()) o.clip.drop_distances_m = DefaultDropDistances(o.drops);
  if (o.drops > 0 && static_cast<int>(o.clip.drop_distances_m.size()) != o.drops)
    throw std::invalid_argument("--drops and --drop-distances name different numbers of drops");
  if (!o.clip.drop_heights_m.empty() && o.clip.drop_distances_m.empty())
    o.clip.drop_distances_m = DefaultDropDistances(static_cast<int>(o.clip.drop_heights_m.size()));
  o.clip.out = o.out;
  if (o.sound || o.audio.chatter || o.audio.hum || o.audio.offset_s != 0 || !o.audio.extra_clicks_s.empty()) {
    o.audio.seed = o.clip.seed;
    o.clip.sound = o.audio;
  }

  const double fps = o.clip.fps;
  const bool quiet = o.quiet;
  const SynthClipResult r = RenderSynthClip(o.clip, [&](int done, int total) {
    if (quiet) return;
    const int per_second = std::max(1, static_cast<int>(std::lround(fps)));
    if (done % per_second == 0 || done == total)
      fmt::print("synth: {:.1f} s of {:.1f} s rendered ({}/{} frames)\n", done / fps, total / fps, done, total),
          std::fflush(stdout);
  });
  std::string apexes;
  for (double h : r.truth.apex_heights_m) apexes += fmt::format("{}{:.3f}", apexes.empty() ? "" : " ", h);
  fmt::print("synth: wrote {} and {}: {} frames {}x{} at {:g} fps in {:.2f} s (cpu {:.2f} s: draw {:.2f}, noise {:.2f}, "
             "encode {:.2f}); apex heights (m): {}\n",
             r.clip_path.string(), r.truth_path.filename().string(), r.truth.frame_count, r.truth.width, r.truth.height,
             r.truth.fps, r.render_wall_s, r.render_cpu_s, r.scene_s, r.noise_s, r.encode_s, apexes);
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
  cmd->add_option("--out,-o", o->out, "Output clip: .avi (MJPEG) or .mp4 (needs FFmpeg); a variable rate: .mp4, .mov or .mkv")
      ->capture_default_str();
  AddBallFlags(cmd, &o->ball);
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
  cmd->add_option("--drops", o->drops,
                  "Several drops in one clip, each at its own distance from a level pinhole camera "
                  "(1.6, 2.6, 1.1, 2.1, 1.3 m in turn unless --drop-distances): the ball bounces to "
                  "rest, rolls to the next distance, is lifted by an unseen hand and dropped again");
  cmd->add_option("--drop-distances", c.drop_distances_m,
                  "Several drops: each drop's distance from the camera, metres, comma-separated")
      ->delimiter(',');
  cmd->add_option("--drop-heights", c.drop_heights_m,
                  "Several drops: each drop's release height, metres, comma-separated (default: "
                  "--drop-height for each)")
      ->delimiter(',');
  cmd->add_option("--approach", c.approach_mps,
                  "Several drops (or --drops 1): the ball moves towards the camera at this speed while "
                  "it bounces, m/s (negative: away)")
      ->capture_default_str();
  cmd->add_option("--camera-pitch", c.camera_pitch_deg,
                  "Several drops (or --drops 1): the camera looks down this much, degrees, raised to "
                  "look at the first drop (0: level)")
      ->capture_default_str();
  cmd->add_option("--roll-time", c.roll_s, "Several drops: the roll from one drop's place to the next, seconds")
      ->capture_default_str();
  cmd->add_option("--lift-time", c.lift_s, "Several drops: the hand's lift to the next release, seconds")
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
  cmd->add_option("--slow-motion", c.timeline.slow_motion,
                  "A phone's slow motion without a tag: frames taken at --fps, those in "
                  "[--slow-from, --slow-to) stamped this many times further apart, factor "
                  "(1 = none; .mp4, .mov or .mkv)")
      ->capture_default_str();
  cmd->add_option("--slow-from", c.timeline.slow_from_s,
                  "Start of the slowed span, real seconds from the first frame")
      ->capture_default_str();
  cmd->add_option("--slow-to", c.timeline.slow_to_s,
                  "End of the slowed span, real seconds from the first frame")
      ->capture_default_str();
  cmd->add_option("--slow-ramp", c.timeline.slow_ramp_s,
                  "The slow-down ramps from 1 to --slow-motion over this long at the slowed span's "
                  "start and back at its end, real seconds")
      ->capture_default_str();
  cmd->add_option("--vfr-min-fps", c.timeline.vfr_min_fps,
                  "A variable frame rate: each frame interval drawn between 1/--fps and 1/this, "
                  "frames per second, stamped as taken (0 = constant; .mp4, .mov or .mkv)")
      ->capture_default_str();
  cmd->add_option("--size", o->size, "Frame size WxH, pixels")->capture_default_str();
  cmd->add_option("--duration", c.duration_s,
                  "Clip length, seconds of real time (a slow-motion file plays longer; several "
                  "drops: until the last rests)")
      ->capture_default_str();
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
  cmd->add_option("--seams", o->seams,
                  "Lines painted on the ball: none, basketball (two great circles and two rings) or tennis "
                  "(one winding curve)")
      ->capture_default_str();
  cmd->add_option("--seam-width", c.seam_width, "A seam line's width, share of the ball's diameter")
      ->capture_default_str();
  cmd->add_option("--seam-color", o->seam_color,
                  "Seam colour B,G,R, 0-255 each (default: 35,35,35 for basketball, 235,235,235 for tennis)");
  cmd->add_option("--spin", c.spin_rps, "The ball's spin, turns per second (its seams turn with it)")
      ->capture_default_str();
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
  cmd->add_option("--chatter-level", o->audio.chatter_rms, "The voices' RMS with --chatter, full scale 1")
      ->capture_default_str();
  cmd->add_option("--hum-level", o->audio.hum_rms, "The hum's RMS with --hum, full scale 1")
      ->capture_default_str();
  cmd->add_option("--click-level", o->audio.click_at_1mps,
                  "A click's peak amplitude at an impact of 1 m/s, full scale 1")
      ->capture_default_str();
  cmd->add_option("--click-exponent", o->audio.click_exponent,
                  "A click's amplitude grows as the impact speed (m/s) to this power")
      ->capture_default_str();
  cmd->add_option("--extra-click", o->audio.extra_clicks_s,
                  "Clicks that are no impact (a hand tapping the ball, a knock) at these picture times, s, "
                  "comma-separated, each as loud as an impact at 1 m/s (implies --sound)")
      ->delimiter(',');
  cmd->add_flag("--quiet,-q", o->quiet, "Print only the final summary line");
  cmd->footer("Example:\n  bouncefit synth --ball softball --drop-height 1.6 --roll 1 --out soft.avi");
  cmd->callback([o] { Run(*o); });
}

}  // namespace bouncefit::cli
