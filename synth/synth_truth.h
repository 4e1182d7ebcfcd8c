#pragma once
// The ground truth of a `bouncefit synth` clip: written next to the clip as
// <clip-stem>.truth.json (clip.avi -> clip.truth.json), read back by tests and benches.
// The file format is documented in docs/FORMATS.md, "synth truth file".
#include <filesystem>
#include <string>
#include <vector>

#include "synth/synth_frame_times.h"

namespace bouncefit {

struct SynthTruthFrame {
  int index = 0;
  double t_s = 0;            // the centre of the frame's exposure, real s (index / fps at a
                             // constant rate)
  double file_t_s = 0;       // its stamp in the file, s (t_s unless the rate varies)
  double cx = 0, cy = 0;     // true ball centre in the image, px (exposure average; origin at
                             // the top-left pixel's centre, y down, after roll)
  double height_m = 0;       // ball bottom above the floor, m (exposure average)
  bool fully_in_view = false;  // the whole ball (every sub-exposure) lies inside the image
  // A held camera (SynthClipConfig::camera_jitter_px): how far the picture has moved since the
  // first frame, px; cx, cy include it.
  double camera_dx = 0, camera_dy = 0;
};

// One drop of a clip with several (synth/synth_drops.h), in clip time.
struct SynthTruthDrop {
  double distance_m = 0;      // from the camera at the release (then nearer by approach_mps a second)
  double approach_mps = 0;    // towards the camera while it bounces
  double px_per_m = 0;        // the image scale at the release's distance
  double radius_px = 0;       // the ball's radius in the picture there
  double floor_offset_px = 0; // its floor line there: image points p on it have p . down = this
  double drop_height_m = 0;
  double release_t_s = 0;
  std::vector<double> impact_times_s;
  std::vector<double> apex_times_s;    // [0] = the release
  std::vector<double> apex_heights_m;  // [0] = drop height
  double rest_t_s = 0;        // the ball lies still from then until it rolls on
};

struct SynthTruth {
  int version = 1;
  std::string clip;          // file name of the clip (no directory)
  double fps = 0;
  int width = 0, height = 0; // px
  int frame_count = 0;
  double px_per_m = 0;       // image scale, px per metre (same along both axes)
  double roll_deg = 0;       // scene rotation about the image centre, counter-clockwise on
                             // screen; true down in the image = (sin roll, cos roll)
  double down_x = 0, down_y = 1;  // that unit vector
  double center_x = 0, center_y = 0;  // rotation centre, px ((width-1)/2, (height-1)/2)
  // Floor line: where the ball bottom touches the floor.
  double floor_y_unrolled_px = 0;  // image y of the floor at the centre column before roll
  double floor_offset_px = 0;      // after roll: points p on the floor have p . down = this
  double floor_point_x = 0, floor_point_y = 0;  // after roll: the floor point below the centre
  double floor_dir_x = 1, floor_dir_y = 0;      // after roll: unit direction along the floor

  std::string ball;          // preset name
  double radius_m = 0, radius_px = 0;
  double mass_kg = 0;
  double restitution = 0, restitution_per_mps = 0, drag_coefficient = 0;
  double ball_color_bgr[3] = {0, 0, 0};
  double g_mps2 = 0;
  double drop_height_m = 0;
  std::string trajectory;    // "point-mass" or what rendered it ("bullet-softbody", ...)

  double camera_jitter_px = 0, camera_sway_px = 0;  // a held camera's (0: a still one)
  double exposure_s = 0;
  int blur_samples = 1;      // sub-exposures averaged per frame (0 = chosen per frame)
  double noise_sigma = 0;    // grey levels
  unsigned long long seed = 0;
  bool distractor = false;

  double launch_up_mps = 0, launch_right_mps = 0;  // a throw's speeds (0: dropped)
  double release_t_s = 0;                  // end of the hold (< 0: before the clip began)
  std::vector<double> impact_times_s;
  // A variable frame rate (SynthTimelineConfig): how it was stamped, and the impacts' and
  // apexes' times on the file's clock (empty at a constant rate, where the clocks are one).
  SynthTimelineConfig timeline;
  std::vector<double> impact_file_times_s, apex_file_times_s;
  int first_apex = 0;                      // index of apex_times_s[0] (> 0: clip began later)
  std::vector<double> apex_times_s;        // [0] = release (or the top of a throw)
  std::vector<double> apex_heights_m;      // [0] = drop height; ball bottom above the floor
  bool comes_to_rest = false;
  double rest_t_s = 0;                     // when comes_to_rest
  // The clip's sound track (synth/synth_audio.h), when it has one.
  bool has_sound = false;
  int sound_sample_rate = 0;
  double sound_offset_s = 0;               // the sound lags the picture by this, s
  bool sound_chatter = false, sound_hum = false;
  // Levels, full scale 1: the room noise's, the voices' and the hum's RMS (when mixed in),
  // a click's peak at 1 m/s and the power of the speed it grows with.
  double sound_noise_rms = 0, sound_chatter_rms = 0, sound_hum_rms = 0;
  double sound_click_at_1mps = 0, sound_click_exponent = 1;
  std::vector<double> impact_speeds_mps;   // one per impact time
  std::vector<double> extra_clicks_s;      // clicks that are no impact (picture time, s)
  // Several drops in one clip: each drop (the fields above hold all of their apexes and
  // impacts, and the first drop's scale and floor); the pinhole camera that saw them.
  std::vector<SynthTruthDrop> drops;
  double camera_focal_px = 0, camera_height_m = 0;
  std::vector<SynthTruthFrame> frames;
};

// clip.avi -> clip.truth.json (same directory).
std::filesystem::path SynthTruthPathFor(const std::filesystem::path& clip);

// Throws std::runtime_error with a one-line message when the file cannot be written.
void WriteSynthTruth(const SynthTruth& truth, const std::filesystem::path& path);

// Throws std::runtime_error with a one-line message ("<path>: ...") on a missing, unreadable
// or malformed file.
SynthTruth LoadSynthTruth(const std::filesystem::path& path);

}  // namespace bouncefit
