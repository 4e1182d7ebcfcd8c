#pragma once
// `bouncefit synth`: drives a ball trajectory through the scene renderer into a video file
// and writes the ground truth next to it (synth/synth_truth.h).
//
// RenderSynthClip simulates the point-mass drop (model/point_mass_drop.h); any other model
// (the soft-body ball of `bouncefit simulate`) renders its own trajectory with
// RenderSynthTrajectoryClip.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "model/ball_model.h"
#include "model/ball_preset.h"
#include "synth/synth_audio.h"
#include "synth/synth_frame_times.h"
#include "synth/synth_scene.h"
#include "synth/synth_truth.h"

namespace bouncefit {

struct SynthClipConfig {
  BallPreset ball = *FindBallPreset("pingpong");  // size, mass, e(v), Cd, colour
  double drop_height_m = 1.0;   // ball bottom above the floor at release, m
  double hold_s = 0.5;          // ball held still before release, s
  // Motion kinds beyond a drop from rest: a throw (vertical speed up positive, horizontal
  // speed to the right, m/s; the horizontal motion is drag-free, the vertical has drag) and
  // a clip that starts this long after the release (mid-bounce; the hold is not shown).
  double launch_up_mps = 0;
  double launch_right_mps = 0;
  double start_after_release_s = 0;
  double g_mps2 = 9.81;
  bool drag = true;             // point-mass physics: quadratic air drag on/off
  double air_density_kgpm3 = 1.2;

  double fps = 120;
  // A variable frame rate: a phone's slow motion (frames taken at fps, a span stamped slowed)
  // or its wandering ordinary rate (synth/synth_frame_times.h); written .mp4, .mov or .mkv.
  SynthTimelineConfig timeline;
  int width = 640, height = 480;  // px
  double duration_s = 5;        // clip length in real time, s (frames = round(duration * fps))
  double px_per_m = 0;          // image scale; 0 = the drop fits the frame height
  double roll_deg = 0;          // camera roll: scene rotated counter-clockwise on screen
  // A camera held in a hand: each frame's picture moved by a jitter of up to this much each
  // way (drawn from the seed) and a sway of this amplitude at 0.7 Hz, px; the first frame is
  // where the camera starts (the truth's per-frame camera_dx, camera_dy: the motion since).
  double camera_jitter_px = 0;
  double camera_sway_px = 0;
  double ball_x = 0.5;          // ball centre, fraction of the width (scene, before roll)
  double floor_y = 0.86;        // floor contact line, fraction of the height (before roll)
  double exposure_s = 0.004;    // motion blur: exposure time centred on each frame time, s
  int blur_samples = 0;         // sub-exposures averaged per frame; 0 = enough for <= 0.5 px
  double noise_sigma = 2.0;     // Gaussian sensor noise, grey levels
  uint64_t seed = 1;
  std::optional<Bgr> ball_bgr;  // default: the preset's colour
  Bgr wall_bgr = {196, 202, 206};
  WallPattern wall_pattern = WallPattern::kPlain;
  Bgr floor_bgr = {112, 118, 124};
  FloorPattern floor_pattern = FloorPattern::kPlain;  // pebbles are a ball's diameter across
  bool distractor = false;      // a static sphere of similar hue on the floor
  // Lines painted on the ball (synth/synth_seams.h), seam_width of its diameter wide, of
  // seam_bgr (default: near-black on a basketball, white on a tennis ball), turning with the
  // ball at spin_rps turns a second.
  SeamPattern seams = SeamPattern::kNone;
  double seam_width = 0.04;
  std::optional<Bgr> seam_bgr;
  double spin_rps = 0;
  // A hand that tosses the ball: an arm reaching in from the frame's nearer side, its hand
  // beside the ball, carrying it at its launch speed for hand_windup_s before the release
  // (the hold is where that starts), then rising on and slowing to a stop over
  // hand_windup_s (an arm's follow-through: it slows as a ball in flight does). Set by tests
  // (tests/tossed_from_the_hand_slow_test.cc); `bouncefit synth` has no flag for it.
  bool hand = false;
  double hand_windup_s = 0.12;
  // Several drops in one clip (synth/synth_drops.h): each drop's distance from the camera, m,
  // and its release height, m (empty: drop_height_m for each). Empty distances: one drop at
  // the scale px_per_m. Between drops the ball rests, rolls for roll_s to the next distance
  // and is lifted for lift_s by an unseen hand, then held for hold_s.
  std::vector<double> drop_distances_m, drop_heights_m;
  double roll_s = 1.0, lift_s = 0.6;
  // ... and while each of those drops bounces, the ball moves towards the camera at this
  // speed, m/s (negative: away): its scale and floor line change from bounce to bounce.
  double approach_mps = 0;
  // ... and the camera of those drops looks down this much, degrees (0: level): it is raised
  // until the first drop's middle is on its axis, so the ball's size in the picture changes as
  // it rises and as it comes closer, and no line of the picture is level with the floor.
  double camera_pitch_deg = 0;
  int quality = 95;             // MJPEG quality, 1-100
  std::filesystem::path out = "synth.avi";  // .avi (MJPEG) or .mp4
  std::optional<SynthAudioConfig> sound;    // a sound track with the impacts' clicks (not .mp4)
};

// A ball trajectory to render. Times are seconds since release; before release the ball is
// held at its state at t = 0.
struct SynthTrajectory {
  std::string name;  // "point-mass", "bullet-softbody", ...
  // Ball state at time t (s since release): bottom and centre height (m), width/height
  // ratio. A centre-bottom distance <= 0 means "round ball of the preset's radius".
  std::function<TrajectorySample(double t_s)> at;
  std::vector<double> impact_times_s;   // since release
  std::vector<double> apex_times_s;     // since release; [0] = release (0)
  std::vector<double> apex_heights_m;   // ball bottom; [0] = drop height
  bool comes_to_rest = false;
  double rest_time_s = 0;               // since release
};

// A model's recorded trajectory (SimulationResult::trajectory, times since release, evenly
// or unevenly sampled) as a SynthTrajectory, linearly interpolated; held at the ends.
// drop_height_m becomes apex 0.
SynthTrajectory SynthTrajectoryFromSimulation(const SimulationResult& result,
                                              double drop_height_m, const std::string& name);

struct SynthClipResult {
  SynthTruth truth;
  std::filesystem::path clip_path, truth_path;
  double render_wall_s = 0;  // time spent in all, s
  double render_cpu_s = 0;   // process CPU time spent in all, s
  // Of which (process CPU time, s): drawing frames, adding noise, encoding the video.
  double scene_s = 0, noise_s = 0, encode_s = 0;
};

// Called after each frame written: (frames done, frame count).
using SynthProgress = std::function<void(int, int)>;

// Throws std::invalid_argument (one line) for a config no clip can be rendered from.
void ValidateSynthClipConfig(const SynthClipConfig& config);

// Validates the config (std::invalid_argument, one line), renders and writes clip + truth
// (several drops: synth/synth_drops.h)
// (std::runtime_error, one line, on I/O failures).
SynthClipResult RenderSynthClip(const SynthClipConfig& config,
                                const SynthProgress& progress = {});
SynthClipResult RenderSynthTrajectoryClip(const SynthClipConfig& config,
                                          const SynthTrajectory& trajectory,
                                          const SynthProgress& progress = {});

// The point-mass trajectory RenderSynthClip uses, for configs' physics fields.
SynthTrajectory PointMassSynthTrajectory(const SynthClipConfig& config);

}  // namespace bouncefit
