#include "synth/synth_clip.h"

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
#include "synth/synth_noise.h"
#include "synth/synth_video.h"

namespace bouncefit {
namespace {

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void ValidateColor(const Bgr& c, const char* what) {
  for (double v : c)
    Require(v >= 0 && v <= 255, std::string(what) + " colour channels must be in 0-255");
}

void Validate(const SynthClipConfig& c) {
  Require(std::isfinite(c.drop_height_m) && c.drop_height_m >= 0,
          "drop height must be >= 0 m (got " + Num(c.drop_height_m) + ")");
  Require(c.ball.diameter_m > 0, "ball diameter must be > 0 m");
  Require(c.ball.mass_kg > 0, "ball mass must be > 0 kg");
  Require(c.hold_s >= 0, "hold must be >= 0 s (got " + Num(c.hold_s) + ")");
  Require(std::abs(c.launch_up_mps) <= 30 && std::abs(c.launch_right_mps) <= 30,
          "launch speeds must be within +-30 m/s");
  Require(c.start_after_release_s >= 0 && c.start_after_release_s < 60,
          "start after release must be in [0, 60) s");
  Require(c.g_mps2 > 0, "g must be > 0 m/s^2");
  Require(c.fps > 0 && c.fps <= 1000, "fps must be in (0, 1000] (got " + Num(c.fps) + ")");
  Require(c.width >= 16 && c.height >= 16 && c.width <= 8192 && c.height <= 8192,
          "size must be between 16x16 and 8192x8192 px");
  Require(c.duration_s > 0, "duration must be > 0 s (got " + Num(c.duration_s) + ")");
  Require(c.duration_s * c.fps <= 1e6, "clip too long (more than a million frames)");
  Require(c.px_per_m >= 0, "px per metre must be >= 0 (0 = fit the drop into the frame)");
  Require(std::abs(c.roll_deg) <= 90, "roll must be in [-90, 90] degrees");
  Require(c.camera_jitter_px >= 0 && c.camera_jitter_px <= 50, "camera jitter must be in 0-50 px");
  Require(c.camera_sway_px >= 0 && c.camera_sway_px <= 100, "camera sway must be in 0-100 px");
  Require(c.ball_x >= 0 && c.ball_x <= 1, "ball x must be a fraction of the width, 0-1");
  Require(c.floor_y > 0.1 && c.floor_y <= 1, "floor y must be a fraction of the height, 0.1-1");
  Require(c.exposure_s >= 0 && c.exposure_s <= 1 / c.fps + 1e-12,
          "exposure must be in [0, 1/fps] s (got " + Num(c.exposure_s) + ")");
  Require(c.blur_samples >= 0 && c.blur_samples <= 256, "blur samples must be in 0-256");
  Require(c.noise_sigma >= 0 && c.noise_sigma <= 100, "noise must be in 0-100 grey levels");
  Require(c.quality >= 1 && c.quality <= 100, "quality must be in 1-100");
  if (c.sound) {
    const std::string e = c.sound->Validate();
    Require(e.empty(), e);
    Require(c.out.extension() == ".avi", "a clip with sound must be .avi (MJPEG + PCM)");
  }
  if (c.ball_bgr) ValidateColor(*c.ball_bgr, "ball");
  ValidateColor(c.wall_bgr, "wall");
  ValidateColor(c.floor_bgr, "floor");
}

// A hand's jitter (uniform, fresh each frame, from the seed) and sway (0.7 Hz), less where
// they put the first frame.
class HeldCamera {
 public:
  explicit HeldCamera(const SynthClipConfig& c) : c_(c) {
    std::mt19937_64 rng(c.seed * 0x9E3779B97F4A7C15ull + 17);
    std::uniform_real_distribution<double> u(-1, 1);
    const int n = std::max(1, static_cast<int>(std::lround(c.duration_s * c.fps)));
    for (int i = 0; i < n; ++i) jitter_.emplace_back(u(rng), u(rng));
  }
  cv::Point2d At(int i) const {
    if (c_.camera_jitter_px == 0 && c_.camera_sway_px == 0) return {0, 0};
    return Raw(i) - Raw(0);
  }

 private:
  cv::Point2d Raw(int i) const {
    const double w = 2 * std::numbers::pi * 0.7 * i / c_.fps;
    const cv::Point2d j = jitter_[static_cast<size_t>(i) % jitter_.size()];
    return {c_.camera_jitter_px * j.x + c_.camera_sway_px * std::sin(w),
            c_.camera_jitter_px * j.y + c_.camera_sway_px * std::cos(w)};
  }
  const SynthClipConfig& c_;
  std::vector<cv::Point2d> jitter_;
};

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// CPU time of the whole process (encoder threads included), s: on a shared machine the
// phases' wall times mostly measure the neighbours.
double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Ball state (scene px and metres) at clip time t.
struct BallAt {
  BallShape shape;
  double bottom_m;
};

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
  Validate(config);
  return RenderSynthTrajectoryClip(config, PointMassSynthTrajectory(config), progress);
}

SynthClipResult RenderSynthTrajectoryClip(const SynthClipConfig& c, const SynthTrajectory& traj,
                                          const SynthProgress& progress) {
  Validate(c);
  if (!traj.at) throw std::invalid_argument("trajectory has no sampling function");
  const auto start = Clock::now();
  const double cpu_start = CpuSeconds();

  const double r_m = c.ball.radius_m();
  const double floor_px = c.floor_y * (c.height - 1);
  double scale = c.px_per_m;
  if (scale == 0) {
    const double top_margin = 0.06 * c.height;
    scale = (floor_px - top_margin) / (c.drop_height_m + 2 * r_m);
    Require(scale > 0, "cannot fit the drop into the frame; give --px-per-m");
  }
  const double ball_x_px = c.ball_x * (c.width - 1);
  const int frame_count = std::max(1, static_cast<int>(std::lround(c.duration_s * c.fps)));

  SynthSceneConfig sc;
  sc.width = c.width;
  sc.height = c.height;
  sc.roll_deg = c.roll_deg;
  sc.floor_y_px = floor_px;
  sc.wall_bgr = c.wall_bgr;
  sc.wall_pattern = c.wall_pattern;
  sc.floor_bgr = c.floor_bgr;
  sc.floor_pattern = c.floor_pattern;
  sc.pebble_px = std::max(4.0, 2 * r_m * scale);
  const Bgr preset_bgr = {c.ball.color_bgr[0], c.ball.color_bgr[1], c.ball.color_bgr[2]};
  sc.ball_bgr = c.ball_bgr.value_or(preset_bgr);
  sc.distractor = c.distractor;
  sc.distractor_radius_px = std::max(3.0, 1.3 * r_m * scale);
  // Opposite side of the image from the ball, resting on the floor.
  sc.distractor_x_px = (c.ball_x <= 0.5 ? 0.8 : 0.2) * (c.width - 1);
  const SynthScene scene(sc);

  // Trajectory time (since release) = clip time + offset.
  const double offset = c.start_after_release_s > 0 ? c.start_after_release_s : -c.hold_s;
  auto ball_at = [&](double t_clip) {
    const double t_flight = std::max(0.0, t_clip + offset);
    const TrajectorySample s = traj.at(t_flight);
    double half_h = s.center_height_m - s.bottom_height_m;
    if (!(half_h > 0)) half_h = r_m;
    const double ratio = s.width_height_ratio > 0 ? s.width_height_ratio : 1.0;
    BallAt b;
    b.bottom_m = s.bottom_height_m;
    b.shape.x = ball_x_px + c.launch_right_mps * t_flight * scale;
    b.shape.y = floor_px - (s.bottom_height_m + half_h) * scale;
    b.shape.b = half_h * scale;
    b.shape.a = ratio * half_h * scale;
    return b;
  };

  cv::VideoWriter writer = OpenSynthVideo(c.out, c.fps, {c.width, c.height}, c.quality);
  SynthNoise noise(c.noise_sigma, c.seed);

  SynthTruth truth;
  truth.clip = c.out.filename().string();
  truth.fps = c.fps;
  truth.width = c.width;
  truth.height = c.height;
  truth.frame_count = frame_count;
  truth.px_per_m = scale;
  truth.roll_deg = c.roll_deg;
  const double th = c.roll_deg * std::numbers::pi / 180;
  truth.down_x = std::sin(th);
  truth.down_y = std::cos(th);
  truth.center_x = (c.width - 1) / 2.0;
  truth.center_y = (c.height - 1) / 2.0;
  truth.floor_y_unrolled_px = floor_px;
  const cv::Point2d fp = scene.ToImage({truth.center_x, floor_px});
  truth.floor_point_x = fp.x;
  truth.floor_point_y = fp.y;
  truth.floor_offset_px = fp.x * truth.down_x + fp.y * truth.down_y;
  truth.floor_dir_x = std::cos(th);
  truth.floor_dir_y = -std::sin(th);
  truth.ball = c.ball.name;
  truth.radius_m = r_m;
  truth.radius_px = r_m * scale;
  truth.mass_kg = c.ball.mass_kg;
  truth.restitution = c.ball.restitution;
  truth.restitution_per_mps = c.ball.restitution_per_mps;
  truth.drag_coefficient = c.drag ? c.ball.drag_coefficient : 0.0;
  for (int i = 0; i < 3; ++i) truth.ball_color_bgr[i] = sc.ball_bgr[i];
  truth.g_mps2 = c.g_mps2;
  truth.drop_height_m = c.drop_height_m;
  truth.trajectory = traj.name;
  truth.exposure_s = c.exposure_s;
  truth.blur_samples = c.exposure_s > 0 ? c.blur_samples : 1;
  truth.noise_sigma = c.noise_sigma;
  truth.seed = c.seed;
  truth.distractor = c.distractor;
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
  truth.comes_to_rest = traj.comes_to_rest && in_clip(traj.rest_time_s);
  truth.rest_t_s = truth.comes_to_rest ? traj.rest_time_s - offset : 0;

  // Where a hand holds the camera in frame i, relative to the first frame: the picture moves by it.
  const HeldCamera held(c);
  truth.camera_jitter_px = c.camera_jitter_px;
  truth.camera_sway_px = c.camera_sway_px;
  cv::Mat frame, moved;
  double scene_s = 0, noise_s = 0, encode_s = 0;
  std::vector<BallShape> subs;
  truth.frames.reserve(frame_count);
  for (int i = 0; i < frame_count; ++i) {
    const double t = i / c.fps;
    int n = 1;
    if (c.exposure_s > 0) {
      n = c.blur_samples;
      if (n == 0) {  // enough sub-exposures that the ball moves <= 0.5 px between them
        double len = 0;
        BallShape prev;
        for (int k = 0; k <= 8; ++k) {
          const BallShape b = ball_at(t - c.exposure_s / 2 + c.exposure_s * k / 8).shape;
          if (k) len += std::hypot(b.x - prev.x, b.y - prev.y) + std::abs(b.b - prev.b);
          prev = b;
        }
        n = std::clamp(static_cast<int>(std::ceil(len / 0.5)), 1, 64);
      }
    }
    subs.clear();
    SynthTruthFrame f;
    f.index = i;
    f.t_s = t;
    f.fully_in_view = true;
    for (int k = 0; k < n; ++k) {
      const double ts = n == 1 ? t : t - c.exposure_s / 2 + c.exposure_s * (k + 0.5) / n;
      const BallAt b = ball_at(ts);
      subs.push_back(b.shape);
      const cv::Point2d p = scene.ToImage({b.shape.x, b.shape.y});
      f.cx += p.x / n;
      f.cy += p.y / n;
      f.height_m += b.bottom_m / n;
      f.fully_in_view = f.fully_in_view && scene.FullyInView(b.shape);
    }
    const cv::Point2d camera = held.At(i);
    f.cx += camera.x, f.cy += camera.y;
    f.camera_dx = camera.x, f.camera_dy = camera.y;
    truth.frames.push_back(f);
    const double t0 = CpuSeconds();
    scene.Render(subs, &frame);
    if (camera != cv::Point2d(0, 0)) {
      // What the scene showed at p, the sensor shows at p + camera (the edges mirrored in).
      const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, camera.x, 0, 1, camera.y);
      cv::warpAffine(frame, moved, m, frame.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
      std::swap(frame, moved);
    }
    const double t1 = CpuSeconds();
    noise.Add(&frame);
    const double t2 = CpuSeconds();
    writer.write(frame);
    const double t3 = CpuSeconds();
    scene_s += t1 - t0;
    noise_s += t2 - t1;
    encode_s += t3 - t2;
    if (progress) progress(i + 1, frame_count);
  }
  const double t_release = CpuSeconds();
  writer.release();
  encode_s += CpuSeconds() - t_release;

  if (c.sound) AddClipSound(c, traj, &truth);

  SynthClipResult result;
  result.clip_path = c.out;
  result.truth_path = SynthTruthPathFor(c.out);
  WriteSynthTruth(truth, result.truth_path);
  result.truth = std::move(truth);
  result.scene_s = scene_s;
  result.noise_s = noise_s;
  result.encode_s = encode_s;
  result.render_wall_s = Seconds(Clock::now() - start);
  result.render_cpu_s = CpuSeconds() - cpu_start;
  return result;
}

}  // namespace bouncefit
