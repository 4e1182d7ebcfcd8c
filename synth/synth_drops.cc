#include "synth/synth_drops.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "model/point_mass_drop.h"
#include "synth/synth_frames.h"

namespace bouncefit {
namespace {

// 0 to 1 with zero speed at both ends: a hand's or a roll's start and stop.
double Smooth(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3 - 2 * u);
}

double HeightOf(const SynthClipConfig& c, size_t k) {
  return c.drop_heights_m.empty() ? c.drop_height_m : c.drop_heights_m[k];
}

// One drop on the clip's clock.
struct PlannedDrop {
  double distance_m = 0, x_m = 0, height_m = 0;
  double release_t = 0;   // the hand lets go
  std::shared_ptr<PointMassDropResult> sim;  // its clock: 0 at the release
  double rest_t = 0;      // lies still from here
  double roll_t = 0;      // rolls on to the next drop's place from here (last drop: the clip ends)
  double lift_t = 0;      // the next drop's lift begins (after the roll and a pause)
};

// Drop k of c, from its release: the point-mass ball's bounces to rest.
PointMassDropResult SimulateDrop(const SynthClipConfig& c, size_t k) {
  PointMassDropConfig pm;
  pm.ball = c.ball;
  pm.drop_height_m = HeightOf(c, k);
  pm.g_mps2 = c.g_mps2;
  pm.air_density_kgpm3 = c.air_density_kgpm3;
  pm.drag = c.drag;
  pm.end_time_s = 40;
  return SimulatePointMassDrop(pm);
}

constexpr double kSettleS = 0.3;  // still on the floor before it rolls, and after

std::vector<PlannedDrop> PlanDrops(const SynthClipConfig& c, const SynthPinhole& cam) {
  std::vector<PlannedDrop> drops;
  const double cx = (c.width - 1) / 2.0;
  double t = c.hold_s;
  for (size_t k = 0; k < c.drop_distances_m.size(); ++k) {
    PlannedDrop d;
    d.distance_m = c.drop_distances_m[k];
    d.height_m = HeightOf(c, k);
    // Left and right of where the first drop is, in turn, within the picture.
    const double shift[3] = {0, 0.15, -0.15};
    const double x_frac = std::clamp(c.ball_x + shift[k % 3], 0.15, 0.85);
    d.x_m = (x_frac * (c.width - 1) - cx) * cam.See(0, 0, d.distance_m).depth_m / cam.focal_px;
    d.sim = std::make_shared<PointMassDropResult>(SimulateDrop(c, k));
    if (!d.sim->comes_to_rest)
      throw std::invalid_argument("drop " + std::to_string(k + 1) + " does not come to rest within 40 s");
    d.release_t = t;
    d.rest_t = t + d.sim->rest_time_s;
    d.roll_t = d.rest_t + kSettleS;
    d.lift_t = d.roll_t + c.roll_s + kSettleS;
    t = d.lift_t + c.lift_s + c.hold_s;
    drops.push_back(d);
  }
  return drops;
}

// Where the ball is at clip time t: its distance and lateral place (m) and its bottom's height.
struct WorldBall {
  double distance_m, x_m, bottom_m;
};

WorldBall BallAt(const std::vector<PlannedDrop>& drops, const SynthClipConfig& c, double t) {
  const PlannedDrop& first = drops.front();
  if (t < first.release_t) return {first.distance_m, first.x_m, first.height_m};
  for (size_t k = 0; k < drops.size(); ++k) {
    const PlannedDrop& d = drops[k];
    const bool last = k + 1 == drops.size();
    // Coming towards the camera while it bounces, until it rests.
    const double moved = c.approach_mps * (std::min(t, d.rest_t) - d.release_t);
    if (last || t < d.roll_t) return {d.distance_m - moved, d.x_m, d.sim->At(t - d.release_t).height_m};
    const PlannedDrop& next = drops[k + 1];
    if (t < next.release_t) {
      const double from = d.distance_m - moved;
      const double roll = Smooth((t - d.roll_t) / c.roll_s);
      const double lift = Smooth((t - d.lift_t) / c.lift_s);
      return {from + (next.distance_m - from) * roll, d.x_m + (next.x_m - d.x_m) * roll, next.height_m * lift};
    }
  }
  return {first.distance_m, first.x_m, 0};  // not reached
}

}  // namespace

SynthPinhole::View SynthPinhole::See(double x_m, double up_m, double distance_m) const {
  const double above = up_m - height_m;
  const double c = std::cos(pitch_rad), s = std::sin(pitch_rad);
  View v;
  v.depth_m = distance_m * c - above * s;
  v.right = x_m / v.depth_m;
  v.down = (-above * c - distance_m * s) / v.depth_m;
  return v;
}

SynthPinhole FitSynthPinhole(const SynthClipConfig& c) {
  const double r = c.ball.radius_m();
  const double cy = (c.height - 1) / 2.0;
  double top = 0, far = 0;
  for (size_t k = 0; k < c.drop_distances_m.size(); ++k) {
    top = std::max(top, HeightOf(c, k) + 2 * r);
    far = std::max(far, c.drop_distances_m[k]);
  }
  SynthPinhole cam;
  cam.pitch_rad = c.camera_pitch_deg * M_PI / 180;
  // Level with the middle of the highest drop; looking down, raised until the first drop's
  // middle is on the axis.
  cam.height_m = 0.5 * top + c.drop_distances_m.front() * std::tan(cam.pitch_rad);
  // Each drop's release top and floor line inside the picture, 5% from its top and bottom edges;
  // a ball that comes closer as it bounces, its floor line where it rests too.
  double reach = 0;
  for (size_t k = 0; k < c.drop_distances_m.size(); ++k) {
    const double d = c.drop_distances_m[k];
    for (double up : {HeightOf(c, k) + 2 * r, 0.0}) reach = std::max(reach, std::abs(cam.See(0, up, d).down));
    if (c.approach_mps > 0) {
      const double nearest = d - c.approach_mps * SimulateDrop(c, k).rest_time_s;
      if (nearest > 0) reach = std::max(reach, std::abs(cam.See(0, 0, nearest).down));
    }
  }
  cam.focal_px = (cy - 0.05 * c.height) / reach;
  cam.wall_distance_m = 1.25 * far;
  return cam;
}

SynthClipResult RenderSynthDropsClip(const SynthClipConfig& c, const SynthProgress& progress) {
  ValidateSynthClipConfig(c);
  if (c.drop_distances_m.empty()) throw std::invalid_argument("several drops need their distances");
  if (c.sound) throw std::invalid_argument("a clip of several drops has no sound track");
  if (c.launch_up_mps != 0 || c.launch_right_mps != 0 || c.start_after_release_s != 0)
    throw std::invalid_argument("several drops are dropped from rest: no throw, no late start");
  const auto wall_start = std::chrono::steady_clock::now();
  const double cpu_start = SynthCpuSeconds();
  const SynthPinhole cam = FitSynthPinhole(c);
  const std::vector<PlannedDrop> drops = PlanDrops(c, cam);
  for (const PlannedDrop& d : drops)
    if (d.distance_m - c.approach_mps * d.sim->rest_time_s < 0.2)
      throw std::invalid_argument("the ball would come within 0.2 m of the camera: less --approach");
  const double r = c.ball.radius_m();
  const double cx = (c.width - 1) / 2.0, cy = (c.height - 1) / 2.0;
  auto floor_y = [&](double distance) { return cy + cam.focal_px * cam.See(0, 0, distance).down; };
  // The scale at a distance: px per m of height at the ball's centre there, at rest.
  auto px_per_m = [&](double distance) { return cam.focal_px / cam.See(0, r, distance).depth_m; };

  const SynthScene scene(SynthSceneConfigOf(c, floor_y(cam.wall_distance_m), r * px_per_m(drops[0].distance_m)));
  auto ball_at = [&](double t) {
    const WorldBall w = BallAt(drops, c, t);
    const SynthPinhole::View v = cam.See(w.x_m, w.bottom_m + r, w.distance_m);
    SynthBallAt b;
    b.bottom_m = w.bottom_m;
    b.shape.x = cx + cam.focal_px * v.right;
    b.shape.y = cy + cam.focal_px * v.down;
    b.shape.a = b.shape.b = r * cam.focal_px / v.depth_m;
    b.shape.floor_y = floor_y(w.distance_m);
    return b;
  };

  SynthTruth truth = SynthTruthHeader(c, scene, px_per_m(drops[0].distance_m), floor_y(drops[0].distance_m));
  truth.trajectory = "point-mass";
  truth.drop_height_m = drops[0].height_m;
  truth.release_t_s = drops[0].release_t;
  truth.camera_focal_px = cam.focal_px;
  truth.camera_height_m = cam.height_m;
  const double end = drops.back().rest_t + 0.5;
  const std::vector<SynthFrameTime> frame_times = SynthFrameTimes(c.timeline, c.fps, end, c.seed);
  truth.frame_count = static_cast<int>(frame_times.size());
  for (const PlannedDrop& d : drops) {
    SynthTruthDrop td;
    td.distance_m = d.distance_m;
    td.approach_mps = c.approach_mps;
    td.px_per_m = px_per_m(d.distance_m);
    td.radius_px = r * td.px_per_m;
    const cv::Point2d fp = scene.ToImage({cx, floor_y(d.distance_m)});
    td.floor_offset_px = fp.x * truth.down_x + fp.y * truth.down_y;
    td.drop_height_m = d.height_m;
    td.release_t_s = d.release_t;
    for (double t : d.sim->impact_times_s) td.impact_times_s.push_back(d.release_t + t);
    for (double t : d.sim->apex_times_s) td.apex_times_s.push_back(d.release_t + t);
    td.apex_heights_m = d.sim->apex_heights_m;
    td.rest_t_s = d.rest_t;
    truth.impact_times_s.insert(truth.impact_times_s.end(), td.impact_times_s.begin(), td.impact_times_s.end());
    truth.apex_times_s.insert(truth.apex_times_s.end(), td.apex_times_s.begin(), td.apex_times_s.end());
    truth.apex_heights_m.insert(truth.apex_heights_m.end(), td.apex_heights_m.begin(), td.apex_heights_m.end());
    truth.drops.push_back(std::move(td));
  }
  truth.comes_to_rest = true;
  truth.rest_t_s = drops.back().rest_t;

  const SynthRenderCost times = RenderSynthFrames(c, scene, frame_times, ball_at, &truth, progress);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return FinishSynthClip(c, std::move(truth), times, wall_s, cpu_start);
}

}  // namespace bouncefit
