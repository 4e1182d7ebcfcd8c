#include "synth/synth_clip.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>

#include "model/point_mass_drop.h"
#include "synth/synth_audio_mux.h"
#include "synth/synth_drops.h"
#include "synth/synth_frames.h"
#include "synth/synth_stamped_video.h"

namespace bouncefit {
namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

void ValidateColor(const Bgr& c, const char* what) {
  for (double v : c)
    Require(v >= 0 && v <= 255, std::string(what) + " colour channels must be in 0-255");
}

}  // namespace

void ValidateSynthClipConfig(const SynthClipConfig& c) {
  Require(std::isfinite(c.drop_height_m) && c.drop_height_m >= 0,
          fmt::format("drop height must be >= 0 m (got {:g})", c.drop_height_m));
  Require(c.ball.diameter_m > 0, "ball diameter must be > 0 m");
  Require(c.ball.mass_kg > 0, "ball mass must be > 0 kg");
  Require(c.hold_s >= 0, fmt::format("hold must be >= 0 s (got {:g})", c.hold_s));
  Require(std::abs(c.launch_up_mps) <= 30 && std::abs(c.launch_right_mps) <= 30,
          "launch speeds must be within +-30 m/s");
  Require(c.start_after_release_s >= 0 && c.start_after_release_s < 60,
          "start after release must be in [0, 60) s");
  Require(c.g_mps2 > 0, "g must be > 0 m/s^2");
  Require(c.fps > 0 && c.fps <= 1000, fmt::format("fps must be in (0, 1000] (got {:g})", c.fps));
  Require(c.width >= 16 && c.height >= 16 && c.width <= 8192 && c.height <= 8192,
          "size must be between 16x16 and 8192x8192 px");
  Require(c.duration_s > 0, fmt::format("duration must be > 0 s (got {:g})", c.duration_s));
  Require(c.duration_s * c.fps <= 1e6, "clip too long (more than a million frames)");
  Require(c.px_per_m >= 0, "px per metre must be >= 0 (0 = fit the drop into the frame)");
  Require(std::abs(c.roll_deg) <= 90, "roll must be in [-90, 90] degrees");
  Require(c.camera_jitter_px >= 0 && c.camera_jitter_px <= 50, "camera jitter must be in 0-50 px");
  Require(c.camera_sway_px >= 0 && c.camera_sway_px <= 100, "camera sway must be in 0-100 px");
  Require(c.ball_x >= 0 && c.ball_x <= 1, "ball x must be a fraction of the width, 0-1");
  Require(c.floor_y > 0.1 && c.floor_y <= 1, "floor y must be a fraction of the height, 0.1-1");
  Require(c.exposure_s >= 0 && c.exposure_s <= 1 / c.fps + 1e-12,
          fmt::format("exposure must be in [0, 1/fps] s (got {:g})", c.exposure_s));
  Require(c.blur_samples >= 0 && c.blur_samples <= 256, "blur samples must be in 0-256");
  Require(c.noise_sigma >= 0 && c.noise_sigma <= 100, "noise must be in 0-100 grey levels");
  Require(c.quality >= 1 && c.quality <= 100, "quality must be in 1-100");
  if (c.sound) {
    const std::string e = c.sound->Validate();
    Require(e.empty(), e);
    Require(c.out.extension() == ".avi", "a clip with sound must be .avi (MJPEG + PCM)");
  }
  const std::string timeline = c.timeline.Validate(c.fps);
  Require(timeline.empty(), timeline);
  Require(!(c.sound && c.timeline.Variable()), "a clip with sound has a constant frame rate");
  if (c.timeline.Variable()) {
    const std::string problem = StampedVideoProblem(c.out, {c.width, c.height});
    Require(problem.empty(), problem);
  }
  if (c.ball_bgr) ValidateColor(*c.ball_bgr, "ball");
  Require(c.seam_width > 0 && c.seam_width <= 0.2, "seam width must be in (0, 0.2] of the ball's diameter");
  if (c.seam_bgr) ValidateColor(*c.seam_bgr, "seam");
  Require(std::abs(c.spin_rps) <= 50, "spin must be within +-50 turns a second");
  ValidateColor(c.wall_bgr, "wall");
  ValidateColor(c.floor_bgr, "floor");
  Require(c.drop_heights_m.empty() || c.drop_heights_m.size() == c.drop_distances_m.size(),
          "give as many drop heights as drop distances");
  for (double d : c.drop_distances_m)
    Require(std::isfinite(d) && d >= 0.2 && d <= 50, "drop distances must be in 0.2-50 m");
  for (double h : c.drop_heights_m)
    Require(std::isfinite(h) && h > 0 && h <= 20, "drop heights must be in (0, 20] m");
  Require(std::isfinite(c.approach_mps) && std::abs(c.approach_mps) <= 5, "approach must be within +-5 m/s");
  Require(c.camera_pitch_deg >= 0 && c.camera_pitch_deg <= 60, "the camera's pitch must be 0 to 60 degrees down");
  Require(c.camera_pitch_deg == 0 || !c.drop_distances_m.empty(),
          "a camera looking down needs the drops' distances (--drops)");
  Require(c.roll_s > 0 && c.roll_s <= 30 && c.lift_s > 0 && c.lift_s <= 30,
          "roll and lift times must be in (0, 30] s");
}

namespace {

// Impact speed from the trajectory itself (any model): the fall over the last 0.1 ms.
double ImpactSpeed(const SynthTrajectory& traj, double t_since_release, double g) {
  const double dt = 1e-4;
  const double before = traj.at(t_since_release - dt).bottom_height_m;
  const double at = traj.at(t_since_release).bottom_height_m;
  return std::max(0.0, (before - at) / dt + 0.5 * g * dt);
}

// Renders the clicks of the truth's impacts and muxes them into the written clip.
void AddClipSound(const SynthClipConfig& c, const SynthTrajectory& traj, SynthTruth* truth) {
  truth->impact_speeds_mps.clear();
  for (double t : truth->impact_times_s)
    truth->impact_speeds_mps.push_back(ImpactSpeed(traj, t - c.hold_s, c.g_mps2));
  const double duration = truth->frame_count / c.fps;
  AddSoundTrack(c.out, RenderSynthAudio(*c.sound, duration, truth->impact_times_s,
                                        truth->impact_speeds_mps),
                c.sound->sample_rate);
  truth->has_sound = true;
  truth->sound_sample_rate = c.sound->sample_rate;
  truth->sound_offset_s = c.sound->offset_s;
  truth->sound_chatter = c.sound->chatter;
  truth->sound_hum = c.sound->hum;
  truth->sound_noise_rms = c.sound->noise_rms;
  truth->sound_chatter_rms = c.sound->chatter_rms;
  truth->sound_hum_rms = c.sound->hum_rms;
  truth->sound_click_at_1mps = c.sound->click_at_1mps;
  truth->sound_click_exponent = c.sound->click_exponent;
  truth->extra_clicks_s = c.sound->extra_clicks_s;
}

// The file's time of real time t (s since the first frame), between the frames' stamps.
double FileTimeAt(const std::vector<SynthFrameTime>& times, double t) {
  auto it = std::upper_bound(times.begin(), times.end(), t,
                             [](double v, const SynthFrameTime& f) { return v < f.real_s; });
  if (it == times.begin()) return t - times.front().real_s + times.front().file_s;
  if (it == times.end()) return t - times.back().real_s + times.back().file_s;
  const SynthFrameTime& b = *it;
  const SynthFrameTime& a = *(it - 1);
  return a.file_s + (t - a.real_s) / (b.real_s - a.real_s) * (b.file_s - a.file_s);
}

}  // namespace

SynthTrajectory PointMassSynthTrajectory(const SynthClipConfig& c) {
  PointMassDropConfig pm;
  pm.ball = c.ball;
  pm.drop_height_m = c.drop_height_m;
  pm.hold_s = 0;
  pm.launch_speed_mps = c.launch_up_mps;
  pm.g_mps2 = c.g_mps2;
  pm.air_density_kgpm3 = c.air_density_kgpm3;
  pm.drag = c.drag;
  // The clip's last frame on the drop's clock (the hold is not shown when it starts later).
  const double offset = c.start_after_release_s > 0 ? c.start_after_release_s : -c.hold_s;
  pm.end_time_s = std::max(0.0, c.duration_s + offset) + c.exposure_s + 0.01;
  auto result = std::make_shared<PointMassDropResult>(SimulatePointMassDrop(pm));
  SynthTrajectory t;
  t.name = "point-mass";
  const double r = c.ball.radius_m();
  t.at = [result, r](double ts) {
    const double h = result->At(ts).height_m;
    return TrajectorySample{ts, h, h + r, 1.0};
  };
  t.impact_times_s = result->impact_times_s;
  t.apex_times_s = result->apex_times_s;
  t.apex_heights_m = result->apex_heights_m;
  t.comes_to_rest = result->comes_to_rest;
  t.rest_time_s = result->rest_time_s;
  return t;
}

SynthTrajectory SynthTrajectoryFromSimulation(const SimulationResult& result,
                                              double drop_height_m, const std::string& name) {
  if (result.trajectory.empty())
    throw std::invalid_argument("simulation result has no recorded trajectory");
  SynthTrajectory t;
  t.name = name;
  auto samples = std::make_shared<std::vector<TrajectorySample>>(result.trajectory);
  t.at = [samples](double ts) {
    const auto& s = *samples;
    if (ts <= s.front().t_s) return s.front();
    if (ts >= s.back().t_s) return s.back();
    auto it = std::upper_bound(s.begin(), s.end(), ts,
                               [](double v, const TrajectorySample& x) { return v < x.t_s; });
    const TrajectorySample& b = *it;
    const TrajectorySample& a = *(it - 1);
    const double w = (b.t_s > a.t_s) ? (ts - a.t_s) / (b.t_s - a.t_s) : 1.0;
    return TrajectorySample{ts, a.bottom_height_m + w * (b.bottom_height_m - a.bottom_height_m),
                            a.center_height_m + w * (b.center_height_m - a.center_height_m),
                            a.width_height_ratio +
                                w * (b.width_height_ratio - a.width_height_ratio)};
  };
  t.impact_times_s = result.impact_times_s;
  t.apex_times_s = {0.0};
  t.apex_heights_m = {drop_height_m};
  t.apex_times_s.insert(t.apex_times_s.end(), result.apex_times_s.begin(),
                        result.apex_times_s.end());
  t.apex_heights_m.insert(t.apex_heights_m.end(), result.bounce_heights_m.begin(),
                          result.bounce_heights_m.end());
  return t;
}

SynthClipResult RenderSynthClip(const SynthClipConfig& config, const SynthProgress& progress) {
  ValidateSynthClipConfig(config);
  if (!config.drop_distances_m.empty()) return RenderSynthDropsClip(config, progress);
  return RenderSynthTrajectoryClip(config, PointMassSynthTrajectory(config), progress);
}

SynthClipResult RenderSynthTrajectoryClip(const SynthClipConfig& c, const SynthTrajectory& traj,
                                          const SynthProgress& progress) {
  ValidateSynthClipConfig(c);
  if (!traj.at) throw std::invalid_argument("trajectory has no sampling function");
  const auto start = Clock::now();
  const double cpu_start = SynthCpuSeconds();

  const double r_m = c.ball.radius_m();
  const double floor_px = c.floor_y * (c.height - 1);
  double scale = c.px_per_m;
  if (scale == 0) {
    const double top_margin = 0.06 * c.height;
    scale = (floor_px - top_margin) / (c.drop_height_m + 2 * r_m);
    Require(scale > 0, "cannot fit the drop into the frame; give --px-per-m");
  }
  const double ball_x_px = c.ball_x * (c.width - 1);
  const std::vector<SynthFrameTime> frame_times =
      SynthFrameTimes(c.timeline, c.fps, c.duration_s, c.seed);

  const SynthScene scene(SynthSceneConfigOf(c, floor_px, r_m * scale));

  // Trajectory time (since release) = clip time + offset.
  const double offset = c.start_after_release_s > 0 ? c.start_after_release_s : -c.hold_s;
  const double windup = c.hand ? c.hand_windup_s : 0;
  auto ball_at = [&](double t_clip) {
    const double t_since = t_clip + offset;  // since the release
    const double t_flight = std::max(0.0, t_since);
    const TrajectorySample s = traj.at(t_flight);
    double half_h = s.center_height_m - s.bottom_height_m;
    if (!(half_h > 0)) half_h = r_m;
    const double ratio = s.width_height_ratio > 0 ? s.width_height_ratio : 1.0;
    SynthBallAt b;
    // Carried by the hand before the release: at the launch speed, in a straight line.
    const double carried = std::clamp(t_since, -windup, 0.0);
    b.bottom_m = s.bottom_height_m + c.launch_up_mps * carried;
    b.shape.x = ball_x_px + c.launch_right_mps * (t_flight + carried) * scale;
    b.shape.y = floor_px - (b.bottom_m + half_h) * scale;
    b.shape.b = half_h * scale;
    b.shape.a = ratio * half_h * scale;
    if (c.hand) {
      // The hand's own path: it reaches in to the ball over the first part of the hold, then
      // the ball's path to the release; after it, slowing evenly to a stop.
      const double after = std::clamp(t_since, 0.0, windup);
      const double on = windup > 0 ? after - after * after / (2 * windup) : 0;
      const bool from_right = c.ball_x > 0.5;
      const double side = from_right ? 1 : -1, r_px = half_h * scale;
      const double reach_s = 0.5 * std::max(0.0, c.hold_s - windup);
      const double reach_u = reach_s > 0 ? std::clamp((t_since + c.hold_s) / reach_s, 0.0, 1.0) : 1.0;
      const double reach = 1 - reach_u * reach_u * (3 - 2 * reach_u);  // still to go, 1 -> 0
      b.has_hand = true;
      b.hand.r = 1.5 * r_px;
      b.hand.x = ball_x_px + c.launch_right_mps * (carried + on) * scale + side * (1.8 + 6 * reach) * r_px;
      b.hand.y = floor_px - (c.drop_height_m + c.launch_up_mps * (carried + on)) * scale - (1 - 2 * reach) * r_px;
      b.hand.edge_x = from_right ? c.width - 1 : 0;
    }
    return b;
  };

  SynthTruth truth = SynthTruthHeader(c, scene, scale, floor_px);
  truth.frame_count = static_cast<int>(frame_times.size());
  truth.drop_height_m = c.drop_height_m;
  truth.trajectory = traj.name;
  truth.launch_up_mps = c.launch_up_mps;
  truth.launch_right_mps = c.launch_right_mps;
  truth.release_t_s = -offset;  // negative: released before the clip began
  const double last_t = c.duration_s;
  auto in_clip = [&](double t_flight) {
    return t_flight - offset >= 0 && t_flight - offset <= last_t;
  };
  for (double t : traj.impact_times_s)
    if (in_clip(t)) truth.impact_times_s.push_back(t - offset);
  // Apexes keep their index (apex k follows impact k-1); one before the clip is left out
  // (truth.first_apex says how many were).
  truth.first_apex = 0;
  for (size_t k = 0; k < traj.apex_times_s.size() && k < traj.apex_heights_m.size(); ++k) {
    if (traj.apex_times_s[k] - offset < 0) {
      truth.first_apex = static_cast<int>(k) + 1;
      continue;
    }
    if (in_clip(traj.apex_times_s[k])) {
      truth.apex_times_s.push_back(traj.apex_times_s[k] - offset);
      truth.apex_heights_m.push_back(traj.apex_heights_m[k]);
    }
  }
  truth.timeline = c.timeline;
  if (c.timeline.Variable()) {
    for (double t : truth.impact_times_s)
      truth.impact_file_times_s.push_back(FileTimeAt(frame_times, t));
    for (double t : truth.apex_times_s)
      truth.apex_file_times_s.push_back(FileTimeAt(frame_times, t));
  }
  truth.comes_to_rest = traj.comes_to_rest && in_clip(traj.rest_time_s);
  truth.rest_t_s = truth.comes_to_rest ? traj.rest_time_s - offset : 0;

  const SynthRenderCost times = RenderSynthFrames(c, scene, frame_times, ball_at, &truth, progress);

  if (c.sound) AddClipSound(c, traj, &truth);

  return FinishSynthClip(c, std::move(truth), times, Seconds(Clock::now() - start), cpu_start);
}

}  // namespace bouncefit
