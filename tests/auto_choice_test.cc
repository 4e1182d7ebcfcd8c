// The automatic choice of the ball (track/auto_choice.h), on drawn frames: no choice while
// nothing moves, a dropped ball chosen and confirmed by its fall, a lock that moves without
// a ballistic arc dropped and not chosen again for a while; and, through the tracker, a still
// decoy's lock switched to the dropped ball in time, a brightness lock not swapped for a
// patch of colour beside its path.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "synth/synth_scene.h"
#include "tests/tracker_test_util.h"
#include "track/auto_choice.h"
#include "track/followed_ball.h"
#include "track/tracker.h"

namespace bouncefit {
namespace {

constexpr double kFps = 60, kR = 15;
const cv::Rect kRoi(0, 0, 640, 480);

// What the choice did over a clip, driven as the tracker drives it, with the ball's true
// centre as its sighting once a lock is on it.
struct ChoiceRun {
  int first_choice = -1;  // frame
  cv::Point2d chosen_at;
  int confirmed = -1;     // frame
  std::string confirmed_what;
  struct Drop {
    int frame;
    cv::Point2d at;
    std::string what;
  };
  std::vector<Drop> drops;
  std::vector<std::pair<int, cv::Point2d>> choices;  // frame, where
  int64_t dropped_locks = 0;
};

// `centre(i)`: the orange ball's centre on frame i.
ChoiceRun RunChoice(int frames, const std::function<cv::Point2d(int)>& centre) {
  const TrackerConfig config;
  AutoChoice choice(config);
  FollowedBall ball(config);
  cv::RNG rng(9);
  ChoiceRun run;
  bool locked = false;
  for (int i = 0; i < frames; ++i) {
    const cv::Point2d at = centre(i);
    cv::Mat img(kRoi.height, kRoi.width, CV_8UC3, cv::Scalar(180, 170, 160));
    testing::DrawBall(img, at.x, at.y, kR, cv::Scalar(40, 110, 230));
    const Frame f = testing::DrawnFrame(img, i, kFps, rng);
    if (!locked) {
      const std::optional<BallCandidate> c = choice.Choose(f, kRoi);
      if (!c) continue;
      choice.Adopt(*c);
      ball.Restart(c->r);
      locked = true;
      run.choices.push_back({i, {c->x, c->y}});
      if (run.first_choice < 0) run.first_choice = i, run.chosen_at = {c->x, c->y};
    }
    BallObservation o;
    o.found = true;
    o.cx = static_cast<float>(at.x), o.cy = static_cast<float>(at.y), o.radius_px = static_cast<float>(kR);
    ball.Found(i / kFps, o);
    if (!choice.unconfirmed()) continue;
    const LockReview review = choice.Review(f, kRoi, o, false, ball);
    if (review.verdict == LockReview::Verdict::kConfirmed) {
      run.confirmed = i, run.confirmed_what = review.what;
    } else if (review.verdict == LockReview::Verdict::kDrop) {
      run.drops.push_back({i, at, review.what});
      locked = false;
    }
  }
  run.dropped_locks = choice.dropped_locks();
  return run;
}

// Held still for 20 frames, then dropped (3000 px/s^2).
TEST(AutoChoice, ADroppedBallIsChosenOnceItMovesAndConfirmedByItsFall) {
  const int release = 20;
  const ChoiceRun run = RunChoice(60, [&](int i) {
    const double t = std::max(0, i - release) / kFps;
    return cv::Point2d(320, 60 + 1500 * t * t);
  });
  ASSERT_GE(run.first_choice, release) << "nothing to choose while nothing moves";
  EXPECT_LE(run.first_choice, release + 8);
  const double t = (run.first_choice - release) / kFps;
  EXPECT_LT(std::hypot(run.chosen_at.x - 320, run.chosen_at.y - (60 + 1500 * t * t)), 2 * kR + 1500 * t / kFps * 4)
      << "chosen on the ball";
  ASSERT_GT(run.confirmed, run.first_choice);
  EXPECT_LE(run.confirmed, release + 0.4 * kFps);
  EXPECT_NE(run.confirmed_what.find("confirmed at"), std::string::npos) << run.confirmed_what;
  EXPECT_NE(run.confirmed_what.find("ballistic arc"), std::string::npos) << run.confirmed_what;
  EXPECT_TRUE(run.drops.empty());
  EXPECT_EQ(run.dropped_locks, 0);
}

// A ball swung from side to side (60 px each way, 1.5 times a second): it moves, never
// ballistically. Its lock is dropped once it has moved for auto_drop_moving_s, and where it
// was dropped no choice falls for auto_reject_s.
TEST(AutoChoice, ALockThatMovesWithoutABallisticArcIsDroppedAndNotChosenThereAgain) {
  const TrackerConfig config;
  const ChoiceRun run = RunChoice(240, [](int i) {
    const double a = 2 * std::numbers::pi * 1.5 * i / kFps;
    return cv::Point2d(320 + 60 * std::sin(a), 240);
  });
  ASSERT_GE(run.first_choice, 0);
  EXPECT_EQ(run.confirmed, -1) << run.confirmed_what;
  ASSERT_FALSE(run.drops.empty());
  const ChoiceRun::Drop& drop = run.drops.front();
  EXPECT_GE(drop.frame - run.first_choice, config.auto_drop_moving_s * kFps);
  EXPECT_LE(drop.frame - run.first_choice, 2 * config.auto_drop_moving_s * kFps) << "it moves most of the time";
  EXPECT_EQ(drop.what.rfind("automatic: dropped the lock at", 0), 0u) << drop.what;
  EXPECT_NE(drop.what.find("without a ballistic arc"), std::string::npos) << drop.what;
  EXPECT_GE(run.dropped_locks, 1);
  int later = 0;
  for (const auto& [frame, at] : run.choices) {
    if (frame <= drop.frame || frame >= drop.frame + config.auto_reject_s * kFps) continue;
    ++later;
    EXPECT_GE(std::hypot(at.x - drop.at.x, at.y - drop.at.y), 1.5 * kR + 4) << "frame " << frame;
  }
  EXPECT_GT(later, 0) << "chosen again elsewhere on its way";
}

// Draws `shape` as `scene` renders it (its ball colour) over `image`: a second object.
void DrawOver(const SynthScene& scene, const BallShape& shape, cv::Mat* image) {
  cv::Mat with, diff;
  scene.Render({shape}, &with);
  cv::absdiff(with, scene.background(), diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  with.copyTo(*image, diff > 0);
}

// The automatic lock first falls on a decoy of the ball's colour that slid in and stopped;
// the ball is held still, then dropped. While the lock stands still the finder looks for a
// better candidate only every auto_review_s: the switch to the falling ball may come that
// much later than with a search on every frame, no more.
TEST(Tracker, AStillLockIsReviewedOftenEnoughToSwitchToTheDroppedBall) {
  SynthSceneConfig sc;
  sc.width = 320, sc.height = 480, sc.floor_y_px = 440;
  const SynthScene scene(sc);
  const double fps = 60, r = 10, g_px = 2500, drop_t = 0.6;  // px, px/s^2, s
  auto frame_at = [&](int i) {
    const double t = i / fps;
    BallShape ball, decoy;
    ball.x = 230, ball.y = 80, ball.a = ball.b = r;
    if (t > drop_t) ball.y += std::min(0.5 * g_px * (t - drop_t) * (t - drop_t), sc.floor_y_px - r - 80);
    decoy.x = 40 + 240 * std::min(t, 0.3), decoy.y = 300, decoy.a = decoy.b = r;
    Frame f;
    scene.Render({ball}, &f.image);
    DrawOver(scene, decoy, &f.image);
    f.utime = static_cast<int64_t>(std::llround(t * 1e6));
    f.index = i;
    return f;
  };
  // The first frame after the drop at which the lock is on the ball, and the description.
  auto run = [&](double review_s, std::string* how) {
    TrackerConfig config;
    config.auto_review_s = review_s;
    Tracker tracker(config);
    int first = -1;
    for (int i = 0; i < 72; ++i) {
      const Frame f = frame_at(i);
      const BallObservation o = tracker.Track(f);
      if (first < 0 && f.utime * 1e-6 > drop_t && o.found && std::abs(o.cx - 230) < r) first = i;
    }
    *how = tracker.Describe();
    return first;
  };
  std::string how_every, how_review;
  const int every = run(0, &how_every);
  const int reviewed = run(0.05, &how_review);
  std::printf("on the ball from frame %d searching every frame, %d every 0.05 s (drop at frame %.0f)\n  %s\n",
              every, reviewed, drop_t * fps, how_review.c_str());
  ASSERT_GE(every, 0) << how_every;
  ASSERT_GE(reviewed, 0) << how_review;
  EXPECT_NE(how_review.find("dropped or replaced"), std::string::npos) << "the decoy was locked first: " << how_review;
  EXPECT_NE(how_review.find("ballistic"), std::string::npos) << how_review;
  EXPECT_LE(reviewed - every, static_cast<int>(std::ceil(0.05 * fps))) << how_review;
}

// A colourless ball is followed by brightness until its fall proves it ballistic; a candidate
// of the finder with a colour is the same ball only where the ball was when the finder saw it.
// At 20 fps a falling ball moves nearly two radii a frame: a patch of colour that moved beside
// the ball's path a frame ago (the finder's middle frame), 2.7 radii from where the ball is
// now but 3.2 from where it was then, is something else (a shaken copy of the shared football
// clip lost its drop to a patch of the door this way).
TEST(Tracker, AFallingBrightnessLockIsNotSwappedForAColourPatchBesideItsPath) {
  SynthSceneConfig sc;
  sc.width = 400, sc.height = 600, sc.floor_y_px = 580;
  sc.wall_bgr = {60, 62, 64};
  sc.floor_bgr = {40, 42, 44};
  sc.ball_bgr = {238, 238, 238};
  const SynthScene ball_scene(sc);
  sc.ball_bgr = {20, 120, 250};
  const SynthScene patch_scene(sc);
  const double fps = 20, r = 30, g_px = 6000, drop_t = 0.3, x = 150;  // px, px/s^2, s
  auto ball_y = [&](double t) { return 80 + (t > drop_t ? 0.5 * g_px * (t - drop_t) * (t - drop_t) : 0.0); };
  const int patch_frame = 9;  // the patch moves between frames 8 and 9 and is gone in 10
  auto frame_at = [&](int i) {
    const double t = i / fps;
    BallShape ball;
    ball.x = x, ball.y = ball_y(t), ball.a = ball.b = r;
    Frame f;
    ball_scene.Render({ball}, &f.image);
    if (i == patch_frame - 1 || i == patch_frame) {
      BallShape patch;
      patch.a = patch.b = r;
      patch.x = x + 2.7 * r + (i == patch_frame ? 0 : -8);
      patch.y = ball_y((patch_frame + 1) / fps);
      DrawOver(patch_scene, patch, &f.image);
    }
    f.utime = static_cast<int64_t>(std::llround(t * 1e6));
    f.index = i;
    return f;
  };
  Tracker tracker{TrackerConfig{}};
  int on_ball = 0, checked = 0;
  std::string track;
  for (int i = 0; i < 15; ++i) {
    const Frame f = frame_at(i);
    const BallObservation o = tracker.Track(f);
    const double t = i / fps;
    track += fmt::format("  frame {}: ball at {:.0f},{:.0f}; {} {:.1f},{:.1f}\n", i, x, ball_y(t),
                         o.found ? "found at" : "not found", o.cx, o.cy);
    if (i > patch_frame && ball_y(t) + r < sc.floor_y_px - 5) {
      ++checked;
      on_ball += o.found && std::hypot(o.cx - x, o.cy - ball_y(t)) < 0.5 * r;
    }
  }
  std::printf("%s%s\n", track.c_str(), tracker.Describe().c_str());
  ASSERT_GE(checked, 3) << track;
  EXPECT_EQ(on_ball, checked) << track << tracker.Describe();
}

}  // namespace
}  // namespace bouncefit
