// The clip renderer behind `bouncefit synth` (synth/synth_clip.h): decoding the rendered clip
// finds the ball where the truth file says, the truth's apexes are the physics', roll and
// squash are honoured, a seed fixes the bytes; its truth file (synth/synth_truth.h) reads back
// what was written and refuses broken ones.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "model/arc_apex.h"
#include "model/point_mass_drop.h"
#include "synth/synth_clip.h"
#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::ScratchDir;

// A small, clean clip: no noise, no blur.
SynthClipConfig CleanConfig(const std::filesystem::path& out) {
  SynthClipConfig c;
  c.ball = *FindBallPreset("airball");
  c.drop_height_m = 0.8;
  c.hold_s = 0.2;
  c.width = 320;
  c.height = 240;
  c.fps = 120;
  c.duration_s = 1.5;
  c.noise_sigma = 0;
  c.exposure_s = 0;
  c.out = out;
  return c;
}

std::vector<cv::Mat> Decode(const std::filesystem::path& clip) {
  cv::VideoCapture cap(clip.string());
  EXPECT_TRUE(cap.isOpened()) << clip;
  std::vector<cv::Mat> frames;
  cv::Mat f;
  while (cap.read(f)) frames.push_back(f.clone());
  return frames;
}

// Pixels whose chroma (max - min channel) is above the grey wall's and floor's. A low
// threshold keeps the ball's shaded side: a higher one biases the centroid to the lit side.
cv::Mat ColouredMask(const cv::Mat& bgr, int threshold = 20) {
  cv::Mat mask(bgr.size(), CV_8U);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) {
      const auto& p = bgr.at<cv::Vec3b>(y, x);
      const int chroma = std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
      mask.at<uchar>(y, x) = chroma > threshold ? 255 : 0;
    }
  return mask;
}

struct Blob {
  bool found = false;
  double cx = 0, cy = 0;
  int count = 0;
  cv::Rect box;
};

Blob Centroid(const cv::Mat& mask) {
  const cv::Moments m = cv::moments(mask, true);
  Blob b;
  b.count = cv::countNonZero(mask);
  if (b.count < 5) return b;
  b.found = true;
  b.cx = m.m10 / m.m00;
  b.cy = m.m01 / m.m00;
  b.box = cv::boundingRect(mask);
  return b;
}

Blob LocateBall(const cv::Mat& bgr) { return Centroid(ColouredMask(bgr)); }

// Per-pixel median of the decoded frames: the background, as the ball moves on.
cv::Mat MedianBackground(const std::vector<cv::Mat>& frames) {
  cv::Mat bg(frames[0].size(), CV_32FC3);
  std::vector<uchar> v(frames.size());
  for (int y = 0; y < bg.rows; ++y)
    for (int x = 0; x < bg.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        for (size_t i = 0; i < frames.size(); ++i) v[i] = frames[i].at<cv::Vec3b>(y, x)[c];
        std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
        bg.at<cv::Vec3f>(y, x)[c] = v[v.size() / 2];
      }
  return bg;
}

// The ball's centre from its outline, independent of its shading: along 64 rays from the
// rough centre, the point where the colour distance to the background falls to half its
// value just inside the ball (the 50 % coverage edge), then a least-squares circle through
// them, refitted without outliers (rays into the shadow). A centroid of thresholded pixels
// would lean towards the ball's lit side.
struct Circle {
  bool found = false;
  double cx = 0, cy = 0, r = 0;
};

Circle FitCircle(const std::vector<cv::Point2d>& p) {
  // Kasa: x^2 + y^2 + a x + b y + c = 0.
  cv::Mat A(static_cast<int>(p.size()), 3, CV_64F), rhs(static_cast<int>(p.size()), 1, CV_64F);
  for (int i = 0; i < A.rows; ++i) {
    A.at<double>(i, 0) = p[i].x;
    A.at<double>(i, 1) = p[i].y;
    A.at<double>(i, 2) = 1;
    rhs.at<double>(i) = -(p[i].x * p[i].x + p[i].y * p[i].y);
  }
  cv::Mat sol;
  Circle c;
  if (p.size() < 8 || !cv::solve(A, rhs, sol, cv::DECOMP_SVD)) return c;
  c.cx = -sol.at<double>(0) / 2;
  c.cy = -sol.at<double>(1) / 2;
  c.r = std::sqrt(c.cx * c.cx + c.cy * c.cy - sol.at<double>(2));
  c.found = std::isfinite(c.r);
  return c;
}

Circle LocateBallOutline(const cv::Mat& frame, const cv::Mat& background) {
  const Blob rough = LocateBall(frame);
  if (!rough.found) return {};
  const double r0 = std::sqrt(rough.count / std::numbers::pi);
  auto dist = [&](double x, double y) {  // bilinear colour distance to the background
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= frame.cols || y0 + 1 >= frame.rows) return -1.0;
    const double fx = x - x0, fy = y - y0;
    double d2 = 0;
    for (int c = 0; c < 3; ++c) {
      auto at = [&](int xx, int yy) {
        return frame.at<cv::Vec3b>(yy, xx)[c] - background.at<cv::Vec3f>(yy, xx)[c];
      };
      const double v = (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
                       fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
      d2 += v * v;
    }
    return std::sqrt(d2);
  };
  std::vector<cv::Point2d> edge;
  for (int k = 0; k < 64; ++k) {
    const double th = 2 * std::numbers::pi * k / 64, ux = std::cos(th), uy = std::sin(th);
    auto at = [&](double rho) { return dist(rough.cx + rho * ux, rough.cy + rho * uy); };
    const double inside = at(r0 - 2.5), outside = at(r0 + 3.5);
    if (inside < 0 || outside < 0 || outside > 0.2 * inside) continue;
    const double mid = 0.5 * (inside + outside);
    double prev_rho = r0 - 2.5, prev = inside;
    for (double rho = r0 - 2.5 + 0.05; rho <= r0 + 3.5; rho += 0.05) {
      const double d = at(rho);
      if (d < mid) {
        const double e = prev_rho + (prev - mid) / (prev - d) * (rho - prev_rho);
        edge.emplace_back(rough.cx + e * ux, rough.cy + e * uy);
        break;
      }
      prev_rho = rho, prev = d;
    }
  }
  Circle c = FitCircle(edge);
  if (!c.found) return c;
  std::vector<cv::Point2d> inliers;
  for (const auto& p : edge)
    if (std::abs(std::hypot(p.x - c.cx, p.y - c.cy) - c.r) < 0.4) inliers.push_back(p);
  return FitCircle(inliers);
}

// Ball-bottom height above the floor (m) of an image centre, by the truth's geometry.
double HeightOf(const SynthTruth& t, double cx, double cy) {
  return (t.floor_offset_px - (cx * t.down_x + cy * t.down_y)) / t.px_per_m - t.radius_m;
}

// Decoded centres of the fully-in-view frames (others: not found).
std::vector<Circle> DecodedCentres(const SynthClipResult& r) {
  const auto frames = Decode(r.clip_path);
  EXPECT_EQ(static_cast<int>(frames.size()), r.truth.frame_count);
  const cv::Mat bg = MedianBackground(frames);
  std::vector<Circle> out(frames.size());
  for (const auto& f : r.truth.frames)
    if (f.fully_in_view && f.index < static_cast<int>(frames.size()))
      out[f.index] = LocateBallOutline(frames[f.index], bg);
  return out;
}

void ExpectDecodedBallMatchesTruth(const SynthClipResult& r, double tolerance_px,
                                   double min_fraction_checked = 0.75) {
  const auto found = DecodedCentres(r);
  int checked = 0;
  double worst = 0;
  for (const auto& f : r.truth.frames) {
    if (!f.fully_in_view) continue;
    const Circle& b = found[f.index];
    ASSERT_TRUE(b.found) << "frame " << f.index;
    const double err = std::hypot(b.cx - f.cx, b.cy - f.cy);
    worst = std::max(worst, err);
    EXPECT_LT(err, tolerance_px) << "frame " << f.index << " found (" << b.cx << ", " << b.cy
                                 << ") truth (" << f.cx << ", " << f.cy << ")";
    EXPECT_NEAR(b.r, r.truth.radius_px, 0.5) << "frame " << f.index;
    ++checked;
  }
  EXPECT_GE(checked, r.truth.frame_count * min_fraction_checked);
  std::printf("checked %d frames, worst centre error %.3f px\n", checked, worst);
}

TEST(Synth, CleanClipPutsTheBallWhereTheTruthSays) {
  const auto dir = ScratchDir("synth_clean");
  const auto r = RenderSynthClip(CleanConfig(dir / "clean.avi"));
  EXPECT_EQ(r.truth_path, dir / "clean.truth.json");
  EXPECT_GT(r.truth.radius_px, 10);
  ExpectDecodedBallMatchesTruth(r, 0.5);
}

TEST(Synth, SmallBallAndCustomColoursToo) {
  const auto dir = ScratchDir("synth_small");
  auto c = CleanConfig(dir / "small.avi");
  c.ball = *FindBallPreset("pingpong");  // ~5 px radius here
  c.ball_bgr = Bgr{200, 60, 30};         // blue
  c.wall_bgr = {250, 250, 250};          // white wall
  c.ball_x = 0.3;
  const auto r = RenderSynthClip(c);
  EXPECT_LT(r.truth.radius_px, 6);
  EXPECT_EQ(r.truth.ball_color_bgr[0], 200);
  ExpectDecodedBallMatchesTruth(r, 0.5);
  const auto frames = Decode(r.clip_path);
  EXPECT_GT(frames[0].at<cv::Vec3b>(5, 160)[1], 235);  // top of the wall: white
}

TEST(Synth, RollIsHonoured) {
  const auto dir = ScratchDir("synth_roll");
  auto c = CleanConfig(dir / "roll.avi");
  c.roll_deg = 12;
  c.ball_x = 0.4;
  const auto r = RenderSynthClip(c);
  const double th = 12 * std::numbers::pi / 180;
  EXPECT_NEAR(r.truth.down_x, std::sin(th), 1e-12);
  EXPECT_NEAR(r.truth.down_y, std::cos(th), 1e-12);
  ExpectDecodedBallMatchesTruth(r, 0.5);

  // The decoded fall runs along true down.
  const auto frames = Decode(r.clip_path);
  const auto found = DecodedCentres(r);
  std::vector<cv::Point2d> fall;
  for (const auto& f : r.truth.frames)
    if (f.t_s > r.truth.release_t_s + 0.05 && f.t_s < r.truth.impact_times_s[0] && f.fully_in_view)
      fall.emplace_back(found[f.index].cx, found[f.index].cy);
  ASSERT_GT(fall.size(), 20u);
  const cv::Point2d d = fall.back() - fall.front();
  EXPECT_NEAR(std::atan2(d.x, d.y) * 180 / std::numbers::pi, 12.0, 0.2);

  // The floor line of the truth separates wall (bright) from floor (dark) in the image.
  const cv::Mat& img = frames[0];
  int checked = 0;
  for (double s = -120; s <= 120; s += 20) {
    const double x = r.truth.floor_point_x + s * r.truth.floor_dir_x;
    const double y = r.truth.floor_point_y + s * r.truth.floor_dir_y;
    auto grey = [&](double dist) {  // along true down from the floor point
      const int px = static_cast<int>(std::lround(x + dist * r.truth.down_x));
      const int py = static_cast<int>(std::lround(y + dist * r.truth.down_y));
      if (px < 0 || py < 0 || px >= img.cols || py >= img.rows) return -1;
      const auto p = img.at<cv::Vec3b>(py, px);
      return (p[0] + p[1] + p[2]) / 3;
    };
    const int above = grey(-4), below = grey(4);
    if (above < 0 || below < 0) continue;
    EXPECT_GT(above, below + 40) << "at s = " << s;
    ++checked;
  }
  EXPECT_GT(checked, 8);
}

TEST(Synth, ApexHeightsFollowThePhysics) {
  const auto dir = ScratchDir("synth_apex");
  auto c = CleanConfig(dir / "apex.avi");
  c.duration_s = 2.2;
  c.drag = false;
  c.ball.restitution = 0.8;
  c.ball.restitution_per_mps = 0;
  const auto r = RenderSynthClip(c);
  const SynthTruth& t = r.truth;
  ASSERT_GE(t.apex_heights_m.size(), 3u);
  // The truth is the physics: apex ratio e^2 without drag, apex 0 the release.
  EXPECT_DOUBLE_EQ(t.apex_heights_m[0], 0.8);
  EXPECT_DOUBLE_EQ(t.apex_times_s[0], 0.2);
  for (size_t k = 1; k < t.apex_heights_m.size(); ++k)
    EXPECT_NEAR(t.apex_heights_m[k] / t.apex_heights_m[k - 1], 0.64, 1e-9);

  // And the decoded clip shows those apexes: parabola through the decoded heights.
  const auto found = DecodedCentres(r);
  std::vector<double> measured;
  for (size_t k = 1; k < t.apex_times_s.size(); ++k) {
    std::vector<double> ts, hs;
    for (const auto& f : t.frames)
      if (std::abs(f.t_s - t.apex_times_s[k]) < 0.12 && f.fully_in_view) {
        ts.push_back(f.t_s);
        hs.push_back(HeightOf(t, found[f.index].cx, found[f.index].cy));
      }
    const ArcApex apex = FitArcApex(ts, hs);
    ASSERT_TRUE(apex.ok);
    EXPECT_NEAR(apex.height, t.apex_heights_m[k], 0.002) << "apex " << k;
    EXPECT_NEAR(apex.t, t.apex_times_s[k], 0.002) << "apex " << k;
    EXPECT_NEAR(apex.curvature, -9.81, 0.1);
    measured.push_back(apex.height);
  }
  EXPECT_NEAR(measured[1] / measured[0], 0.64, 0.01);
  // The held ball sits at the drop height before release.
  EXPECT_NEAR(HeightOf(t, found[0].cx, found[0].cy), 0.8, 0.002);
}

TEST(Synth, TruthMatchesAnIndependentSimulationWithDrag) {
  const auto dir = ScratchDir("synth_drag");
  auto c = CleanConfig(dir / "drag.avi");
  c.duration_s = 2.0;
  const auto r = RenderSynthClip(c);
  PointMassDropConfig p;
  p.ball = c.ball;
  p.drop_height_m = c.drop_height_m;
  p.hold_s = c.hold_s;
  p.end_time_s = 3;
  const auto sim = SimulatePointMassDrop(p);
  ASSERT_GE(r.truth.apex_heights_m.size(), 2u);
  for (size_t k = 0; k < r.truth.apex_heights_m.size(); ++k) {
    EXPECT_NEAR(r.truth.apex_heights_m[k], sim.apex_heights_m[k], 1e-9);
    EXPECT_NEAR(r.truth.apex_times_s[k], sim.apex_times_s[k], 1e-9);
  }
  for (size_t k = 0; k < r.truth.impact_times_s.size(); ++k)
    EXPECT_NEAR(r.truth.impact_times_s[k], sim.impact_times_s[k], 1e-9);
  for (const auto& f : r.truth.frames) EXPECT_NEAR(f.height_m, sim.At(f.t_s).height_m, 1e-9);
  // Drag loses energy: below the drag-free first rebound.
  const double e = c.ball.RestitutionAt(sim.impact_speeds_mps[0]);
  EXPECT_LT(r.truth.apex_heights_m[1], e * e * c.drop_height_m);
}

TEST(Synth, SameSeedSameBytesOtherSeedOtherNoise) {
  auto c = CleanConfig("");
  c.noise_sigma = 3;
  c.exposure_s = 0.004;
  c.duration_s = 0.5;
  c.out = ScratchDir("synth_seed_a") / "clip.avi";
  const auto a = RenderSynthClip(c);
  c.out = ScratchDir("synth_seed_b") / "clip.avi";
  const auto b = RenderSynthClip(c);
  c.seed = 2;
  c.out = ScratchDir("synth_seed_c") / "clip.avi";
  const auto other = RenderSynthClip(c);
  auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  EXPECT_EQ(slurp(a.clip_path), slurp(b.clip_path));
  EXPECT_EQ(slurp(a.truth_path), slurp(b.truth_path));
  EXPECT_NE(slurp(a.clip_path), slurp(other.clip_path));
  const auto fa = Decode(a.clip_path), fo = Decode(other.clip_path);
  ASSERT_EQ(fa.size(), fo.size());
  cv::Mat diff;
  cv::absdiff(fa[10], fo[10], diff);
  const double mad = cv::mean(diff)[0];
  EXPECT_GT(mad, 1.5);  // two independent sigma-3 noises differ by ~3.4 on average
  EXPECT_LT(mad, 6);
  // The truth does not depend on the noise.
  for (size_t i = 0; i < a.truth.frames.size(); ++i)
    EXPECT_EQ(a.truth.frames[i].cy, other.truth.frames[i].cy);
}

TEST(Synth, NoiseHasTheRequestedSigma) {
  auto c = CleanConfig(ScratchDir("synth_noise") / "noisy.avi");
  c.duration_s = 0.1;
  c.noise_sigma = 4;
  c.quality = 100;
  const auto noisy = RenderSynthClip(c);
  c.noise_sigma = 0;
  c.out = c.out.parent_path() / "clean.avi";
  const auto clean = RenderSynthClip(c);
  const auto fn = Decode(noisy.clip_path), fc = Decode(clean.clip_path);
  cv::Mat a, b;
  fn[3].convertTo(a, CV_32F);
  fc[3].convertTo(b, CV_32F);
  cv::Scalar mean, sd;
  const cv::Mat d = a - b;
  cv::meanStdDev(d.reshape(1), mean, sd);
  // JPEG smooths some of it away; chroma subsampling more.
  EXPECT_GT(sd[0], 2.0);
  EXPECT_LT(sd[0], 4.5);
  EXPECT_NEAR(mean[0], 0, 0.3);
}

TEST(Synth, MotionBlurStretchesTheBallAlongItsMotion) {
  const auto dir = ScratchDir("synth_blur");
  auto c = CleanConfig(dir / "sharp.avi");
  const auto sharp = RenderSynthClip(c);
  c.exposure_s = 1 / c.fps;
  c.out = dir / "blur.avi";
  const auto blur = RenderSynthClip(c);
  const auto fs = Decode(sharp.clip_path), fb = Decode(blur.clip_path);
  // Just before the first impact the ball moves fastest.
  const int i = static_cast<int>(std::floor(blur.truth.impact_times_s[0] * c.fps)) - 2;
  const Blob bs = LocateBall(fs[i]), bb = LocateBall(fb[i]);
  // The ball moves ~one frame's displacement during a 1/fps exposure.
  const double motion_px = blur.truth.frames[i + 1].cy - blur.truth.frames[i - 1].cy;
  EXPECT_GT(motion_px, 8);
  EXPECT_GT(bb.box.height, bs.box.height + 0.25 * motion_px);  // faint tails are cut
  EXPECT_NEAR(bb.box.width, bs.box.width, 2);
  // Its centre is the exposure-averaged truth centre.
  EXPECT_NEAR(bb.cx, blur.truth.frames[i].cx, 0.5);
  EXPECT_NEAR(bb.cy, blur.truth.frames[i].cy, 1.0);
  // Falling faster and faster, the exposure average lies below the frame-time centre.
  EXPECT_GT(blur.truth.frames[i].cy, sharp.truth.frames[i].cy);
}

TEST(Synth, HeldBallIsStillAndOutOfViewIsFlagged) {
  const auto dir = ScratchDir("synth_view");
  auto c = CleanConfig(dir / "big.avi");
  c.px_per_m = 400;  // 0.8 m drop does not fit 240 px: starts above the image
  c.duration_s = 1.2;
  const auto r = RenderSynthClip(c);
  EXPECT_FALSE(r.truth.frames[0].fully_in_view);
  EXPECT_LT(r.truth.frames[0].cy, 0);
  EXPECT_TRUE(r.truth.frames.back().fully_in_view);  // bounced down by then
  // Held: identical truth up to release.
  for (const auto& f : r.truth.frames)
    if (f.t_s <= c.hold_s) {
      EXPECT_EQ(f.cy, r.truth.frames[0].cy);
    }
  ExpectDecodedBallMatchesTruth(r, 0.5, 0.4);
}

TEST(Synth, RendersAnyTrajectoryWithSquash) {
  const auto dir = ScratchDir("synth_squash");
  auto c = CleanConfig(dir / "squash.avi");
  c.duration_s = 0.5;
  c.hold_s = 0;
  SimulationResult sim;
  sim.ok = true;
  const double r = c.ball.radius_m();
  for (int i = 0; i <= 100; ++i) {  // sits on the floor, squashed to 1.6 : 1
    const double ratio = 1 + 0.6 * std::min(1.0, i / 50.0);
    const double half_h = r / std::sqrt(ratio);
    sim.trajectory.push_back({i * 0.005, 0.0, half_h, ratio});
  }
  const auto traj = SynthTrajectoryFromSimulation(sim, 0.0, "test-squash");
  const auto res = RenderSynthTrajectoryClip(c, traj);
  EXPECT_EQ(res.truth.trajectory, "test-squash");
  const auto frames = Decode(res.clip_path);
  const Blob first = LocateBall(frames[0]);
  const Blob last = LocateBall(frames.back());
  EXPECT_NEAR(static_cast<double>(first.box.width) / first.box.height, 1.0, 0.1);
  EXPECT_NEAR(static_cast<double>(last.box.width) / last.box.height, 1.6, 0.12);
  EXPECT_NEAR(last.cx, res.truth.frames.back().cx, 0.5);
  EXPECT_NEAR(last.cy, res.truth.frames.back().cy, 0.5);
  // The bottom stays on the floor line.
  const double bottom_y = res.truth.frames.back().cy + r / std::sqrt(1.6) * res.truth.px_per_m;
  EXPECT_NEAR(bottom_y, res.truth.floor_y_unrolled_px, 1e-6);
}

TEST(Synth, DistractorIsAStaticBlobOfSimilarHue) {
  const auto dir = ScratchDir("synth_distractor");
  auto c = CleanConfig(dir / "d.avi");
  c.distractor = true;
  c.ball_x = 0.3;
  c.duration_s = 0.6;
  const auto r = RenderSynthClip(c);
  EXPECT_TRUE(r.truth.distractor);
  const auto frames = Decode(r.clip_path);
  for (int i : {0, 40, 70}) {
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(ColouredMask(frames[i]), labels, stats,
                                                   centroids);
    ASSERT_EQ(n, 3) << "frame " << i;  // background, ball, distractor
    bool ball_seen = false, other_right = false;
    for (int k = 1; k < n; ++k) {
      const double x = centroids.at<double>(k, 0), y = centroids.at<double>(k, 1);
      if (std::hypot(x - r.truth.frames[i].cx, y - r.truth.frames[i].cy) < 1) ball_seen = true;
      if (x > 0.7 * c.width) other_right = true;
    }
    EXPECT_TRUE(ball_seen && other_right) << "frame " << i;
  }
}

// Seams painted on the ball cut its colour into panels (a basketball's into four and more in
// view, a tennis ball's into two), in their own colour over a share of it, and turn with it in
// flight; without seams the ball is one coloured disc.
TEST(Synth, SeamsCutTheBallIntoPanelsThatTurnWithIt) {
  const auto dir = ScratchDir("synth_seams");
  struct Case {
    SeamPattern seams;
    int min_panels;
  };
  for (const Case k : {Case{SeamPattern::kNone, 1}, Case{SeamPattern::kBasketball, 4}, Case{SeamPattern::kTennis, 2}}) {
    auto c = CleanConfig(dir / (std::string(SeamPatternName(k.seams)) + ".avi"));
    c.ball = *FindBallPreset("basketball");
    c.px_per_m = 500;  // a ball 120 px across
    c.drop_height_m = 0.15;
    c.duration_s = 0.45;
    c.seams = k.seams;
    c.seam_width = 0.05;
    c.seam_bgr = Bgr{235, 235, 235};
    c.spin_rps = 2;
    const auto r = RenderSynthClip(c);
    const auto frames = Decode(r.clip_path);
    std::vector<cv::Mat> discs;
    for (int i : {30, 42}) {  // in flight, 0.1 s apart: the ball turned by a fifth of a turn
      const SynthTruthFrame& t = r.truth.frames[static_cast<size_t>(i)];
      // The ball's coloured pixels well inside its rim.
      cv::Mat inside = cv::Mat::zeros(frames[static_cast<size_t>(i)].size(), CV_8U);
      cv::circle(inside, cv::Point(static_cast<int>(std::lround(t.cx)), static_cast<int>(std::lround(t.cy))),
                 static_cast<int>(0.9 * r.truth.radius_px), 255, cv::FILLED);
      cv::Mat panels = ColouredMask(frames[static_cast<size_t>(i)], 60) & inside;
      cv::Mat labels;
      const int n = cv::connectedComponents(panels, labels) - 1;
      const double line_share = 1 - cv::countNonZero(panels) / static_cast<double>(cv::countNonZero(inside));
      if (k.seams == SeamPattern::kNone) {
        EXPECT_EQ(n, 1) << "frame " << i;
        EXPECT_LT(line_share, 0.01) << "frame " << i;
      } else {
        EXPECT_GE(n, k.min_panels) << SeamPatternName(k.seams) << " frame " << i;
        EXPECT_GT(line_share, 0.03) << SeamPatternName(k.seams) << " frame " << i;
      }
      const int side = static_cast<int>(1.8 * r.truth.radius_px);
      discs.push_back(panels(cv::Rect(static_cast<int>(std::lround(t.cx - 0.9 * r.truth.radius_px)),
                                      static_cast<int>(std::lround(t.cy - 0.9 * r.truth.radius_px)), side, side))
                          .clone());
    }
    cv::Mat changed;
    cv::bitwise_xor(discs[0], discs[1], changed);
    if (k.seams != SeamPattern::kNone) {
      EXPECT_GT(cv::countNonZero(changed), 0.03 * changed.total()) << SeamPatternName(k.seams) << ": the seams turn";
    }
  }
}

TEST(Synth, Mp4WritesOrSaysWhyNot) {
  auto c = CleanConfig(ScratchDir("synth_mp4") / "clip.mp4");
  c.duration_s = 0.25;
  try {
    const auto r = RenderSynthClip(c);
    EXPECT_EQ(static_cast<int>(Decode(r.clip_path).size()), r.truth.frame_count);
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(".mp4"), std::string::npos) << e.what();
  }
}

TEST(SynthTruth, RoundTripsAndRejectsBadFiles) {
  const auto dir = ScratchDir("synth_truth");
  auto c = CleanConfig(dir / "t.avi");
  c.duration_s = 0.3;
  c.roll_deg = -5;
  const auto r = RenderSynthClip(c);
  const SynthTruth t = LoadSynthTruth(r.truth_path);
  EXPECT_EQ(t.clip, "t.avi");
  EXPECT_EQ(t.frame_count, r.truth.frame_count);
  EXPECT_EQ(t.width, 320);
  EXPECT_DOUBLE_EQ(t.px_per_m, r.truth.px_per_m);
  EXPECT_DOUBLE_EQ(t.roll_deg, -5);
  EXPECT_DOUBLE_EQ(t.floor_offset_px, r.truth.floor_offset_px);
  EXPECT_EQ(t.ball, "airball");
  EXPECT_EQ(t.apex_heights_m, r.truth.apex_heights_m);
  ASSERT_EQ(t.frames.size(), r.truth.frames.size());
  for (size_t i = 0; i < t.frames.size(); ++i) {
    EXPECT_DOUBLE_EQ(t.frames[i].cx, r.truth.frames[i].cx);
    EXPECT_DOUBLE_EQ(t.frames[i].cy, r.truth.frames[i].cy);
    EXPECT_EQ(t.frames[i].fully_in_view, r.truth.frames[i].fully_in_view);
  }

  auto expect_one_line_error = [](const std::filesystem::path& p, const std::string& what) {
    try {
      LoadSynthTruth(p);
      ADD_FAILURE() << "no error for " << what;
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      EXPECT_NE(m.find(p.string()), std::string::npos) << m;
    }
  };
  expect_one_line_error(dir / "missing.truth.json", "a missing file");
  std::ofstream(dir / "garbage.json") << "not json {";
  expect_one_line_error(dir / "garbage.json", "garbage");
  std::ofstream(dir / "other.json") << "{\"fps\": 30}";
  expect_one_line_error(dir / "other.json", "another JSON file");
  // A truncated field list.
  std::ifstream in(r.truth_path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  text.replace(text.find("\"px_per_m\""), 10, "\"px_per_mm\"");
  std::ofstream(dir / "broken.json") << text;
  expect_one_line_error(dir / "broken.json", "a missing field");
}

}  // namespace
}  // namespace bouncefit
