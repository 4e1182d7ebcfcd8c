// The tracker on rendered clips with known truth (bouncefit synth): centre accuracy on all four
// presets, distractors, empty scenes, YUYV input.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>

#include "synth/synth_scene.h"
#include "tests/test_support.h"
#include "tests/tracker_test_util.h"

namespace bouncefit {
namespace {

using testing::ConfigForColor;
using testing::TrackClip;
using testing::TrackScore;

SynthClipResult Render(const std::string& dir, const std::string& ball, double duration_s,
                       bool distractor = false) {
  SynthClipConfig c;
  c.ball = *FindBallPreset(ball);
  c.noise_sigma = 3;
  c.roll_deg = 1;
  c.hold_s = 0.1;
  c.duration_s = duration_s;
  c.distractor = distractor;
  c.out = testing::ScratchDir(dir) / (ball + ".avi");
  return RenderSynthClip(c);
}

void Print(const std::string& what, const TrackScore& s) {
  std::printf("%-10s in view %d lost %d wrong %d | centre error rms %.3f p99 %.3f max %.3f px, "
              "bias %+.3f,%+.3f\n  %s\n",
              what.c_str(), s.in_view, s.lost, s.wrong, s.rms, s.p99, s.max, s.mean_dx,
              s.mean_dy, s.describe.c_str());
}

class TrackerPreset : public ::testing::TestWithParam<std::string> {};

TEST_P(TrackerPreset, CentreWithinAFewTenthsOfAPixel) {
  const std::string ball = GetParam();
  const SynthClipResult clip = Render("tracker_" + ball, ball, 2.0);
  const TrackScore s = TrackClip(clip.clip_path, ConfigForColor(clip.truth.ball_color_bgr, ball),
                                 &clip.truth);
  Print(ball, s);
  ASSERT_GT(s.in_view, 100);
  EXPECT_EQ(s.lost, 0);
  EXPECT_EQ(s.wrong, 0);
  EXPECT_LE(s.rms, 0.3);
  EXPECT_LE(s.p99, 1.0);
}

INSTANTIATE_TEST_SUITE_P(AllPresets, TrackerPreset,
                         ::testing::Values("pingpong", "wiffle", "softball", "airball"));

// Scenes where a choice by saturation alone (the saturated blob that moves) finds nothing: the ball as
// saturated as its wall, a patterned wall, a poster wall that shares the ball's hue
// somewhere. The automatic choice must find the ball by its motion and its contrast with its
// own surroundings, confirm it by its arc, and track it as well as a given colour.
struct BusyWall {
  const char* name;
  const char* ball;
  Bgr ball_bgr, wall_bgr;
  WallPattern pattern;
};

class TrackerBusyWall : public ::testing::TestWithParam<BusyWall> {};

TEST_P(TrackerBusyWall, AutomaticChoiceFindsTheBall) {
  const BusyWall& w = GetParam();
  SynthClipConfig c;
  c.ball = *FindBallPreset(w.ball);
  c.ball_bgr = w.ball_bgr;
  c.wall_bgr = w.wall_bgr;
  c.wall_pattern = w.pattern;
  c.noise_sigma = 3;
  c.roll_deg = 1;
  c.hold_s = 0.1;
  c.duration_s = 1.6;
  c.out = testing::ScratchDir(std::string("tracker_wall_") + w.name) / "clip.avi";
  const SynthClipResult clip = RenderSynthClip(c);
  const TrackScore s = TrackClip(clip.clip_path, TrackerConfig{}, &clip.truth);
  Print(w.name, s);
  EXPECT_EQ(s.wrong, 0);
  // It must see the ball move before it can choose: the first frames of the fall are lost.
  // Before the poster the ball also vanishes where it crosses a patch of its own hue (a
  // brown patch is a dark orange): lost there, never reported on the patch.
  EXPECT_LE(s.lost, w.pattern == WallPattern::kPoster ? 80 : 20);
  EXPECT_LE(s.rms, 0.3);
  EXPECT_NE(s.describe.find("ballistic"), std::string::npos) << s.describe;
}

INSTANTIATE_TEST_SUITE_P(
    Walls, TrackerBusyWall,
    ::testing::Values(
        // The paper's scene: a red ball before a saturated blue wall.
        BusyWall{"red_on_blue", "softball", {40, 40, 210}, {190, 90, 30}, WallPattern::kPlain},
        // A yellow ball before red brick.
        BusyWall{"yellow_on_brick", "tennis", {40, 215, 225}, {50, 60, 150}, WallPattern::kBrick},
        // The orange ping-pong ball before a poster wall of every hue.
        BusyWall{"orange_on_poster", "pingpong", {20, 120, 250}, {196, 202, 206}, WallPattern::kPoster}),
    [](const ::testing::TestParamInfo<BusyWall>& i) { return std::string(i.param.name); });

// A static sphere of similar hue (1.3x the ball's radius) on the floor, a white wall: the
// ball's colour given, then chosen automatically; never a report far from the true ball.
TEST(Tracker, SimilarHueDistractorNeverLocked) {
  const SynthClipResult clip = Render("tracker_distractor", "pingpong", 2.0, true);
  const TrackScore given = TrackClip(
      clip.clip_path, ConfigForColor(clip.truth.ball_color_bgr, "pingpong"), &clip.truth);
  Print("given", given);
  EXPECT_EQ(given.wrong, 0);
  EXPECT_EQ(given.lost, 0);
  EXPECT_LE(given.rms, 0.3);
  const TrackScore automatic = TrackClip(clip.clip_path, TrackerConfig{}, &clip.truth);
  Print("automatic", automatic);
  EXPECT_EQ(automatic.wrong, 0);
  // It needs the ball to move before it can choose: the first frames of the fall are lost.
  EXPECT_LE(automatic.lost, 20);
  EXPECT_NE(automatic.describe.find("moved"), std::string::npos) << automatic.describe;
  EXPECT_LE(automatic.rms, 0.3);
}

// The same clip as a V4L2 camera would deliver it (YUYV 4:2:2): same track as from BGR.
TEST(Tracker, YuyvGivesTheSameAnswerAsBgr) {
  const SynthClipResult clip = Render("tracker_yuyv", "wiffle", 1.2);
  const TrackerConfig config = ConfigForColor(clip.truth.ball_color_bgr, "wiffle");
  const TrackScore bgr = TrackClip(clip.clip_path, config, &clip.truth, false);
  const TrackScore yuyv = TrackClip(clip.clip_path, config, &clip.truth, true);
  Print("bgr", bgr);
  Print("yuyv", yuyv);
  ASSERT_EQ(bgr.obs.size(), yuyv.obs.size());
  double worst = 0;
  for (size_t i = 0; i < bgr.obs.size(); ++i) {
    ASSERT_EQ(bgr.obs[i].found, yuyv.obs[i].found) << "frame " << i;
    if (!bgr.obs[i].found) continue;
    worst = std::max(worst, static_cast<double>(std::hypot(bgr.obs[i].cx - yuyv.obs[i].cx,
                                                           bgr.obs[i].cy - yuyv.obs[i].cy)));
  }
  std::printf("largest BGR-YUYV centre difference %.3f px\n", worst);
  EXPECT_LE(worst, 0.2);
  EXPECT_EQ(yuyv.lost, 0);
  EXPECT_LE(yuyv.rms, 0.3);
}

// Frames of the synth scene with no ball (wall, floor, noise 3, JPEG): nothing is ever found,
// with a colour given or chosen automatically.
TEST(Tracker, NoBallNothingFound) {
  SynthSceneConfig sc;
  sc.roll_deg = 1;
  const SynthScene scene(sc);
  const double orange[3] = {20, 120, 250};
  Tracker given(ConfigForColor(orange, "orange"));
  Tracker automatic{TrackerConfig{}};
  cv::RNG rng(7);
  int found = 0;
  for (int i = 0; i < 60; ++i) {
    cv::Mat noise(scene.background().size(), CV_32FC3), img;
    rng.fill(noise, cv::RNG::NORMAL, 0, 3);
    scene.background().convertTo(img, CV_32FC3);
    img += noise;
    img.convertTo(img, CV_8UC3);
    std::vector<uchar> jpg;
    cv::imencode(".jpg", img, jpg, {cv::IMWRITE_JPEG_QUALITY, 95});
    Frame f;
    f.image = cv::imdecode(jpg, cv::IMREAD_COLOR);
    f.index = i;
    f.utime = i * 8333;
    found += given.Track(f).found;
    found += automatic.Track(f).found;
  }
  EXPECT_EQ(found, 0);
  EXPECT_FALSE(automatic.color_chosen()) << automatic.Describe();
}

// A pixel picked on the first frame sets the colour.
TEST(Tracker, PickedPixelSetsTheColour) {
  const SynthClipResult clip = Render("tracker_pick", "softball", 1.0);
  TrackerConfig config;
  config.has_pick = true;
  config.pick_x = clip.truth.frames[0].cx;
  config.pick_y = clip.truth.frames[0].cy;
  const TrackScore s = TrackClip(clip.clip_path, config, &clip.truth);
  Print("picked", s);
  EXPECT_EQ(s.lost, 0);
  EXPECT_EQ(s.wrong, 0);
  EXPECT_LE(s.rms, 0.3);
  EXPECT_NE(s.describe.find("picked pixel"), std::string::npos);
}

// Light dims to 55% and turns bluish over one second (the ball's own chroma/luma shifts):
// the tracker keeps the ball on every frame, its threshold follows slowly and stays bounded.
TEST(Tracker, FollowsSlowLightingChange) {
  const SynthClipResult clip = Render("tracker_light", "airball", 1.2);
  const int n = clip.truth.frame_count;
  auto dim = [n](int i, cv::Mat* img) {
    const double a = static_cast<double>(i) / n;
    const cv::Scalar gain(1.0 - 0.25 * a, 1.0 - 0.45 * a, 1.0 - 0.6 * a);  // B, G, R
    cv::multiply(*img, gain, *img);
  };
  TrackerConfig config = ConfigForColor(clip.truth.ball_color_bgr, "airball");
  const TrackScore s = TrackClip(clip.clip_path, config, &clip.truth, false, 1 << 30, dim);
  Print("dimming", s);
  EXPECT_EQ(s.lost, 0);
  EXPECT_EQ(s.wrong, 0);
  EXPECT_LE(s.rms, 0.3);
  // The threshold moved towards the ball's new colour (its chroma/luma on the last frames)...
  const ColorModel start = ColorModel::FromBgr(clip.truth.ball_color_bgr[0],
                                               clip.truth.ball_color_bgr[1],
                                               clip.truth.ball_color_bgr[2], {});
  const ColorModel end = ColorModel::FromBgr(clip.truth.ball_color_bgr[0] * 0.75,
                                             clip.truth.ball_color_bgr[1] * 0.55,
                                             clip.truth.ball_color_bgr[2] * 0.4, {});
  const double before = std::hypot(end.nu() - start.nu(), end.nv() - start.nv());
  const double after = std::hypot(end.nu() - s.color_nu, end.nv() - s.color_nv);
  std::printf("colour distance to the dimmed ball: %.3f at start, %.3f at the end\n", before,
              after);
  EXPECT_LT(after, 0.8 * before);
  // ... but no further than the bound (30% of the colour) from where it started.
  EXPECT_LE(std::hypot(s.color_nu - start.nu(), s.color_nv - start.nv()),
            0.3 * std::hypot(start.nu(), start.nv()) + 1e-6);
}

// An ROI over the lower part of the scene: the ball is reported only inside it, accurately
// when wholly inside, and never while it is above it.
TEST(Tracker, RegionOfInterest) {
  const SynthClipResult clip = Render("tracker_roi", "wiffle", 1.6);
  TrackerConfig config = ConfigForColor(clip.truth.ball_color_bgr, "wiffle");
  config.roi_x = 100;
  config.roi_y = 200;
  config.roi_w = 440;
  config.roi_h = 280;
  const TrackScore s = TrackClip(clip.clip_path, config, &clip.truth);
  const double r = clip.truth.radius_px;
  int inside = 0, inside_found = 0, above = 0, above_found = 0;
  double ss = 0;
  for (size_t i = 0; i < s.obs.size(); ++i) {
    const SynthTruthFrame& t = clip.truth.frames[i];
    const BallObservation& o = s.obs[i];
    if (t.cy - r > config.roi_y + 1) {
      ++inside;
      if (o.found) {
        ++inside_found;
        ss += std::pow(std::hypot(o.cx - t.cx, o.cy - t.cy), 2);
      }
    } else if (t.cy + r < config.roi_y - 1) {
      ++above;
      above_found += o.found;
    }
    if (o.found) {
      EXPECT_GE(o.cy, config.roi_y - r) << "frame " << i;
    }
  }
  const double rms = inside_found ? std::sqrt(ss / inside_found) : 0;
  std::printf("ROI: wholly inside %d frames (found %d, rms %.3f px), above it %d (found %d)\n",
              inside, inside_found, rms, above, above_found);
  ASSERT_GT(inside, 50);
  ASSERT_GT(above, 10);
  EXPECT_EQ(inside_found, inside);
  EXPECT_EQ(above_found, 0);
  EXPECT_LE(rms, 0.3);
}

TEST(Tracker, BadInputIsAOneLineError) {
  TrackerConfig bad;
  bad.blur_sigma_px = -1;
  EXPECT_THROW(Tracker{bad}, std::invalid_argument);
  Tracker t{TrackerConfig{}};
  Frame f;
  f.image = cv::Mat(48, 64, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(t.Track(f), std::invalid_argument);
  f.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar(0));
  f.format = PixelFormat::kYuyv;
  EXPECT_THROW(t.Track(f), std::invalid_argument);
  TrackerConfig pick;
  pick.has_pick = true;
  pick.pick_x = 1000;
  Tracker tp{pick};
  f.format = PixelFormat::kBgr24;
  try {
    tp.Track(f);
    ADD_FAILURE() << "pick outside the frame accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

// A bright strip (a reflection, the edge of a door swinging) slides along the floor as a
// white ball, smeared by a phone's exposure, lands on it: about as many pixels as the ball,
// long and thin, merged with it at the impact. Followed by brightness, the lock stays on the
// ball, and the limit on a box's extent (track/ball_extent.h) keeps every smeared frame of it.
// (The real 20 fps clip whose lock slid off with such a strip for 1.4 s is not shared; its
// boxes are checked in tracker_parts_test, BallExtent.*.)
TEST(Tracker, AStripSlidingAlongTheFloorAtTheImpactIsNotTheBall) {
  SynthSceneConfig sc;
  sc.width = 320, sc.height = 480, sc.floor_y_px = 440;
  sc.wall_bgr = {45, 45, 45}, sc.floor_bgr = {35, 35, 35}, sc.ball_bgr = {235, 235, 235};
  const SynthScene scene(sc);
  TrackerConfig config;
  config.luma_mode = true;
  Tracker tracker(config);
  const double fps = 20, r = 6, g_px = 2200, e = 0.8;  // px, px/s^2
  // Centre height above its floor contact, px, at time t: a drop from 332.75 px, landing on
  // the frame at 0.55 s (the strip's and the ball's pixels merge), then bounces.
  const auto height = [&](double t, int* bounce) {
    double v0 = 0, h0 = 332.75, t0 = 0;
    *bounce = 0;
    for (;;) {
      // Falling from h0 with upward speed v0 at t0: lands at t1.
      const double t1 = t0 + (v0 + std::sqrt(v0 * v0 + 2 * g_px * h0)) / g_px;
      if (t < t1) return h0 + v0 * (t - t0) - 0.5 * g_px * (t - t0) * (t - t0);
      v0 = e * g_px * (t1 - t0 - v0 / g_px), h0 = 0, t0 = t1, ++*bounce;
    }
  };
  const double first_impact_s = std::sqrt(2 * 332.75 / g_px);
  int found = 0, wrong = 0, frames_after_lock = 0;
  for (int i = 0; i < 40; ++i) {
    const double t = i / fps;
    int bounce = 0;
    BallShape ball;
    ball.x = 160, ball.y = sc.floor_y_px - r - height(t, &bounce), ball.a = ball.b = r;
    // A phone's exposure: half the frame period, the ball smeared along its path.
    std::vector<BallShape> subs;
    for (int k = 0; k < 8; ++k) {
      BallShape b = ball;
      int ignored = 0;
      b.y = sc.floor_y_px - r - height(t + (k - 3.5) / 8 * 0.5 / fps, &ignored);
      subs.push_back(b);
    }
    Frame f;
    scene.Render(subs, &f.image);
    // The strip: 36 x 6 px, brighter than the floor, sliding right 12 px a frame through the
    // point of impact from two frames before it.
    const int k = i - static_cast<int>(std::floor(first_impact_s * fps)) + 2;
    if (k >= 0) cv::rectangle(f.image, cv::Rect(100 + 12 * k, static_cast<int>(sc.floor_y_px) - 6, 36, 6),
                              cv::Scalar(225, 225, 225), cv::FILLED);
    f.utime = static_cast<int64_t>(std::llround(t * 1e6));
    f.index = i;
    const BallObservation o = tracker.Track(f);
    if (i < 3) continue;
    ++frames_after_lock;
    if (!o.found) continue;
    ++found;
    if (std::hypot(o.cx - ball.x, o.cy - ball.y) > 2 * r) {
      ++wrong;
      ADD_FAILURE() << "frame " << i << " (t " << t << " s, bounce " << bounce << "): found at " << o.cx << ","
                    << o.cy << " (box " << o.w << "x" << o.h << "), the ball is at " << ball.x << "," << ball.y;
    }
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(found, frames_after_lock * 3 / 4) << "the ball itself is followed";
}

// A phone (4K) held close to a ping-pong ball, 24 fps, chosen automatically: the ball is 230 px
// across (smeared to 400 px by its motion), dropped 14 cm before a dark wall onto a wooden
// floor, a strip of its colour sliding down the frame's right border. Returns the frames after
// the drop, those where it was found, found off the ball, and found on the strip.
struct CloseUpScore {
  int in_view = 0, found = 0, far = 0, on_strip = 0;
  std::string how;
};
CloseUpScore TrackCloseUpDrop(const Bgr& ball_bgr) {
  SynthSceneConfig sc;
  sc.width = 720, sc.height = 1400, sc.floor_y_px = 1320;
  sc.wall_bgr = {70, 45, 35}, sc.floor_bgr = {60, 105, 160}, sc.ball_bgr = ball_bgr;
  const SynthScene scene(sc);
  // A 40 mm ball 230 px across: 5750 px/m.
  const double fps = 24, r = 115, g_px = 56400, e = 0.85, h0 = 800, hold_s = 0.3;  // px, px/s^2, s
  // Centre height above its floor contact, px: held, then dropped from h0, then bounces.
  const auto height = [&](double t) {
    if (t < hold_s) return h0;
    double v0 = 0, h = h0, t0 = hold_s;
    for (int bounce = 0; bounce < 20; ++bounce) {
      const double t1 = t0 + (v0 + std::sqrt(v0 * v0 + 2 * g_px * h)) / g_px;
      if (t < t1) return h + v0 * (t - t0) - 0.5 * g_px * (t - t0) * (t - t0);
      v0 = e * g_px * (t1 - t0 - v0 / g_px), h = 0, t0 = t1;
    }
    return 0.0;
  };
  Tracker tracker(TrackerConfig{});
  CloseUpScore score;
  auto& [in_view, found, far, on_strip, how] = score;
  for (int i = 0; i < 40; ++i) {
    const double t = i / fps;
    std::vector<BallShape> subs;  // a phone's exposure: half the frame period
    for (int k = 0; k < 8; ++k) {
      BallShape b;
      b.x = 360, b.y = sc.floor_y_px - r - height(t + (k - 3.5) / 8 * 0.5 / fps), b.a = b.b = r;
      subs.push_back(b);
    }
    Frame f;
    scene.Render(subs, &f.image);
    const cv::Rect strip(sc.width - 9, 100 + 6 * i, 9, 50);
    cv::rectangle(f.image, strip, cv::Scalar(ball_bgr[0], ball_bgr[1], ball_bgr[2]), cv::FILLED);
    f.utime = static_cast<int64_t>(std::llround(t * 1e6));
    f.index = i;
    const BallObservation o = tracker.Track(f);
    if (t < hold_s + 0.1) continue;  // chosen once it has moved
    const double truth_y = sc.floor_y_px - r - height(t);
    ++in_view;
    if (!o.found) continue;
    ++found;
    if (std::abs(o.cx - (sc.width - 5)) < 2 * r && std::abs(o.cy - (strip.y + 25)) < 2 * r) ++on_strip;
    // Within a tenth of the radius of the ball's centre at mid-exposure plus half the smear
    // (the rim is fitted to the round end of a smear, half its length from its middle), away
    // from the impacts (within a frame of one the exposure straddles the bounce).
    const double smear = std::abs(height(t + 0.25 / fps) - height(t - 0.25 / fps));
    bool near_impact = false;
    for (int k = -100; k <= 100; ++k) near_impact = near_impact || height(t + k / 100.0 / fps) < 5;
    if (!near_impact && std::hypot(o.cx - 360, o.cy - truth_y) > 0.1 * r + 0.5 * smear) {
      ++far;
      std::printf("frame %d (t %.3f s): found at %.1f,%.1f r %.1f, the ball is at 360,%.1f\n", i, t, o.cx, o.cy,
                  o.radius_px, truth_y);
    }
  }
  how = tracker.Describe();
  std::printf("found in %d of %d frames after the drop, %d off the ball, %d on the strip\n  %s\n", found, in_view, far,
              on_strip, how.c_str());
  return score;
}

// In colour: larger than the configured box limit (220 px), which grows with the ball followed,
// and with a rim ramp wider than the rim fit looked across (9-10 px: it grows with the ball
// too). Without both the ball was never refined and the lock went to the strip.
TEST(Tracker, ACloseUpBallLargerThanTheBoxLimitIsFollowed) {
  ASSERT_LT(TrackerConfig{}.segment.max_box_px, 230) << "the ball must not fit the configured limit";
  const CloseUpScore s = TrackCloseUpDrop({20, 120, 250});
  EXPECT_GE(s.found, s.in_view * 9 / 10) << s.how;
  EXPECT_EQ(s.far, 0);
  EXPECT_EQ(s.on_strip, 0);
}

// A white ball, followed in brightness: changes of light softer than 32 px are removed from
// the contrast, and that took the inside of a 230 px ball too (a ring was left: 17 of 30
// frames found, 25 px off). For a close-up ball only changes wider than 2.5 radii are.
TEST(Tracker, ACloseUpWhiteBallIsFollowedByItsBrightness) {
  const CloseUpScore s = TrackCloseUpDrop({235, 235, 235});
  EXPECT_NE(s.how.find("brighter than its surroundings"), std::string::npos) << s.how;
  EXPECT_GE(s.found, s.in_view * 9 / 10) << s.how;
  // One frame after a bounce the first, tight window cuts the ball and the cut blob's centroid
  // is taken (26 px off): a known gap, allowed once.
  EXPECT_LE(s.far, 1);
  EXPECT_EQ(s.on_strip, 0);
}

}  // namespace
}  // namespace bouncefit
