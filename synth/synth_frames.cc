#include "synth/synth_frames.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <ctime>
#include <numbers>
#include <random>

#include "synth/synth_noise.h"
#include "synth/synth_stamped_video.h"
#include "synth/synth_video.h"

namespace bouncefit {
namespace {

// A hand's jitter (uniform, fresh each frame, from the seed) and sway (0.7 Hz), less where
// they put the first frame.
class HeldCamera {
 public:
  HeldCamera(const SynthClipConfig& c, int frames) : c_(c) {
    std::mt19937_64 rng(c.seed * 0x9E3779B97F4A7C15ull + 17);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < std::max(1, frames); ++i) jitter_.emplace_back(u(rng), u(rng));
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

}  // namespace

SynthSceneConfig SynthSceneConfigOf(const SynthClipConfig& c, double floor_px, double ball_radius_px) {
  SynthSceneConfig sc;
  sc.width = c.width;
  sc.height = c.height;
  sc.roll_deg = c.roll_deg;
  sc.floor_y_px = floor_px;
  sc.wall_bgr = c.wall_bgr;
  sc.wall_pattern = c.wall_pattern;
  sc.floor_bgr = c.floor_bgr;
  sc.floor_pattern = c.floor_pattern;
  sc.pebble_px = std::max(4.0, 2 * ball_radius_px);
  const Bgr preset_bgr = {c.ball.color_bgr[0], c.ball.color_bgr[1], c.ball.color_bgr[2]};
  sc.ball_bgr = c.ball_bgr.value_or(preset_bgr);
  sc.distractor = c.distractor;
  sc.seams = c.seams;
  sc.seam_width = c.seam_width;
  sc.seam_bgr = c.seam_bgr.value_or(c.seams == SeamPattern::kTennis ? Bgr{235, 235, 235} : Bgr{35, 35, 35});
  sc.distractor_radius_px = std::max(3.0, 1.3 * ball_radius_px);
  // Opposite side of the image from the ball, resting on the floor.
  sc.distractor_x_px = (c.ball_x <= 0.5 ? 0.8 : 0.2) * (c.width - 1);
  return sc;
}

SynthTruth SynthTruthHeader(const SynthClipConfig& c, const SynthScene& scene, double px_per_m,
                            double floor_px) {
  SynthTruth truth;
  truth.clip = c.out.filename().string();
  truth.fps = c.fps;
  truth.width = c.width;
  truth.height = c.height;
  truth.px_per_m = px_per_m;
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
  truth.radius_m = c.ball.radius_m();
  truth.radius_px = truth.radius_m * px_per_m;
  truth.mass_kg = c.ball.mass_kg;
  truth.restitution = c.ball.restitution;
  truth.restitution_per_mps = c.ball.restitution_per_mps;
  truth.drag_coefficient = c.drag ? c.ball.drag_coefficient : 0.0;
  for (int i = 0; i < 3; ++i) truth.ball_color_bgr[i] = scene.config().ball_bgr[i];
  truth.g_mps2 = c.g_mps2;
  truth.exposure_s = c.exposure_s;
  truth.blur_samples = c.exposure_s > 0 ? c.blur_samples : 1;
  truth.noise_sigma = c.noise_sigma;
  truth.seed = c.seed;
  truth.distractor = c.distractor;
  return truth;
}

SynthClipResult FinishSynthClip(const SynthClipConfig& c, SynthTruth truth, const SynthRenderCost& times,
                                double wall_s, double cpu_start_s) {
  SynthClipResult result;
  result.clip_path = c.out;
  result.truth_path = SynthTruthPathFor(c.out);
  WriteSynthTruth(truth, result.truth_path);
  result.truth = std::move(truth);
  result.scene_s = times.scene_s;
  result.noise_s = times.noise_s;
  result.encode_s = times.encode_s;
  result.render_wall_s = wall_s;
  result.render_cpu_s = SynthCpuSeconds() - cpu_start_s;
  return result;
}

double SynthCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

SynthRenderCost RenderSynthFrames(const SynthClipConfig& c, const SynthScene& scene,
                                  const std::vector<SynthFrameTime>& frame_times,
                                  const std::function<SynthBallAt(double)>& ball_at,
                                  SynthTruth* truth, const SynthProgress& progress) {
  const int frame_count = static_cast<int>(frame_times.size());
  truth->frame_count = frame_count;
  cv::VideoWriter writer;
  std::unique_ptr<StampedVideoWriter> stamped;
  if (c.timeline.Variable())
    stamped = std::make_unique<StampedVideoWriter>(c.out, cv::Size(c.width, c.height), c.quality);
  else
    writer = OpenSynthVideo(c.out, c.fps, {c.width, c.height}, c.quality);
  SynthNoise noise(c.noise_sigma, c.seed);
  // Where a hand holds the camera in frame i, relative to the first frame: the picture moves by it.
  const HeldCamera held(c, frame_count);
  truth->camera_jitter_px = c.camera_jitter_px;
  truth->camera_sway_px = c.camera_sway_px;
  SynthRenderCost times;
  cv::Mat frame, moved;
  std::vector<BallShape> subs;
  double spin_rad = 0, spun_to_s = -1e301;  // the ball's turn, and the time it was last taken at
  BallShape last_spun;
  truth->frames.reserve(frame_count);
  for (int i = 0; i < frame_count; ++i) {
    const double t = frame_times[static_cast<size_t>(i)].real_s;
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
    f.file_t_s = frame_times[static_cast<size_t>(i)].file_s;
    f.fully_in_view = true;
    for (int k = 0; k < n; ++k) {
      const double ts = n == 1 ? t : t - c.exposure_s / 2 + c.exposure_s * (k + 0.5) / n;
      const SynthBallAt b = ball_at(ts);
      // The ball spins while it moves (in flight, rolling), not while it is held or at rest.
      if (spun_to_s > -1e300 && (b.shape.x != last_spun.x || b.shape.y != last_spun.y))
        spin_rad += 2 * std::numbers::pi * c.spin_rps * (ts - spun_to_s);
      spun_to_s = ts, last_spun = b.shape;
      subs.push_back(b.shape);
      subs.back().spin_rad = spin_rad;
      const cv::Point2d p = scene.ToImage({b.shape.x, b.shape.y});
      f.cx += p.x / n;
      f.cy += p.y / n;
      f.height_m += b.bottom_m / n;
      f.fully_in_view = f.fully_in_view && scene.FullyInView(b.shape);
    }
    const cv::Point2d camera = held.At(i);
    f.cx += camera.x, f.cy += camera.y;
    f.camera_dx = camera.x, f.camera_dy = camera.y;
    truth->frames.push_back(f);
    const double t0 = SynthCpuSeconds();
    const SynthBallAt mid = ball_at(t);
    scene.Render(subs, &frame, mid.has_hand ? &mid.hand : nullptr);
    if (camera != cv::Point2d(0, 0)) {
      // What the scene showed at p, the sensor shows at p + camera (the edges mirrored in).
      const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, camera.x, 0, 1, camera.y);
      cv::warpAffine(frame, moved, m, frame.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
      std::swap(frame, moved);
    }
    const double t1 = SynthCpuSeconds();
    noise.Add(&frame);
    const double t2 = SynthCpuSeconds();
    if (stamped)
      stamped->Write(frame, f.file_t_s);
    else
      writer.write(frame);
    const double t3 = SynthCpuSeconds();
    times.scene_s += t1 - t0;
    times.noise_s += t2 - t1;
    times.encode_s += t3 - t2;
    if (progress) progress(i + 1, frame_count);
  }
  const double t_release = SynthCpuSeconds();
  if (stamped)
    stamped->Close();
  else
    writer.release();
  times.encode_s += SynthCpuSeconds() - t_release;
  return times;
}

}  // namespace bouncefit
