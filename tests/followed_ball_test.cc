// What the tracker knows of the ball it follows (track/followed_ball.h), fed the sightings of
// a ball in flight: the prediction it makes of the next frame, what that frame may expect,
// the camera's shift, losing and restarting a ball, and the size rules every part asks.
#include <gtest/gtest.h>

#include <cmath>

#include "track/ball_extent.h"
#include "track/followed_ball.h"

namespace bouncefit {
namespace {

BallObservation SightingAt(double x, double y, double r) {
  BallObservation o;
  o.found = true;
  o.cx = static_cast<float>(x), o.cy = static_cast<float>(y), o.radius_px = static_cast<float>(r);
  return o;
}

// A ball lobbed sideways at 60 fps (3 px a frame, 2000 px/s^2 down), radius 20 px: its
// centre on frame i.
struct Lob {
  static constexpr double kFps = 60, kG = 2000, kR = 20;
  static double T(int i) { return i / kFps; }
  static double X(int i) { return 100 + 3.0 * i; }
  static double Y(int i) { return 50 + 0.5 * kG * T(i) * T(i); }
};

// The lob's first six frames seen: the next frame's index.
int FollowSixFrames(FollowedBall& ball) {
  Prediction p;
  int i = 0;
  for (; i < 6; ++i) {
    ball.Predict(Lob::T(i), &p);
    ball.Found(Lob::T(i), SightingAt(Lob::X(i), Lob::Y(i), Lob::kR));
  }
  return i;
}

TEST(FollowedBall, PredictsTheNextFrameOfAnArcAndWhatItMayShow) {
  const TrackerConfig config;
  FollowedBall ball(config);
  Prediction p;
  for (int i = 0; i < 15; ++i) {
    const bool predicted = ball.Predict(Lob::T(i), &p);
    EXPECT_EQ(predicted, i > 0) << "frame " << i;
    if (i >= 5) {
      // The arc is a parabola: predicted to a small fraction of a pixel, moving as fast as it flies.
      EXPECT_NEAR(p.at.x, Lob::X(i), 0.01) << "frame " << i;
      EXPECT_NEAR(p.at.y, Lob::Y(i), 0.01) << "frame " << i;
      EXPECT_NEAR(p.motion_px, std::hypot(3, Lob::kG * Lob::T(i) / Lob::kFps), 0.01) << "frame " << i;
      EXPECT_NEAR(p.sweep_px, p.motion_px, 1e-9) << "one frame since the last sighting";
      EXPECT_EQ(ball.expected().motion_px, p.motion_px);
      EXPECT_GT(ball.expected().max_extent_px, 4 * Lob::kR) << "a box as long as the ball and its smear";
    }
    ball.Found(Lob::T(i), SightingAt(Lob::X(i), Lob::Y(i), Lob::kR));
  }
  EXPECT_NEAR(ball.radius(), Lob::kR, 1e-6);
  EXPECT_EQ(ball.lost(), 0);
  // The part of the frame it may be in next: from where it was last seen to where it flies to.
  const cv::Rect2d may_be = ball.WhereBallMayBe(Lob::T(15));
  EXPECT_TRUE(may_be.contains({Lob::X(15), Lob::Y(15)}));
  EXPECT_TRUE(may_be.contains({ball.last_x(), ball.last_y()}));
  EXPECT_LT(may_be.height, 2 * (1.5 * Lob::kR + 8) + Lob::Y(15) - Lob::Y(14) + 1);
}

TEST(FollowedBall, FollowsTheBallInTheSceneWhileTheCameraShifts) {
  const TrackerConfig config;
  FollowedBall still(config), shaken(config);
  Prediction ps, pk;
  for (int i = 0; i < 10; ++i) {
    const double t = Lob::T(i);
    // The camera shakes by up to 6 px: the frame shows the ball shifted by as much.
    const double dx = 6 * std::sin(i), dy = 6 * std::cos(1.7 * i);
    shaken.SetCameraShift(dx, dy);
    const bool a = still.Predict(t, &ps), b = shaken.Predict(t, &pk);
    ASSERT_EQ(a, b);
    if (i >= 4) {
      EXPECT_NEAR(pk.at.x - ps.at.x, dx, 1e-3) << "frame " << i;
      EXPECT_NEAR(pk.at.y - ps.at.y, dy, 1e-3) << "frame " << i;
    }
    still.Found(t, SightingAt(Lob::X(i), Lob::Y(i), Lob::kR));
    shaken.Found(t, SightingAt(Lob::X(i) + dx, Lob::Y(i) + dy, Lob::kR));
  }
}

// A ball seen with its centre unknown (the frame's border cuts it, too little of it in view):
// followed still, frame after frame, on the arc its placed sightings made; its size and last
// centre as they were.
TEST(FollowedBall, ASightingWithItsCentreUnknownKeepsItFollowedOnItsArc) {
  const TrackerConfig config;
  FollowedBall ball(config);
  Prediction p;
  int i = FollowSixFrames(ball);
  const double last_x = ball.last_x(), last_y = ball.last_y();
  for (const int end = i + 5; i < end; ++i) {
    ASSERT_TRUE(ball.Predict(Lob::T(i), &p)) << "frame " << i;
    EXPECT_NEAR(p.at.y, Lob::Y(i), 0.01) << "frame " << i;
    BallObservation unplaced = SightingAt(NAN, NAN, 30);
    EXPECT_FALSE(CentrePlaced(unplaced));
    ball.Found(Lob::T(i), unplaced);
    EXPECT_EQ(ball.lost(), 0);
  }
  EXPECT_EQ(ball.last_x(), last_x);
  EXPECT_EQ(ball.last_y(), last_y);
  EXPECT_NEAR(ball.radius(), Lob::kR, 1e-6);
  EXPECT_NEAR(ball.last_radius(), Lob::kR, 1e-6);
}

TEST(FollowedBall, ALostBallIsPredictedForTwoFramesThenForgotten) {
  TrackerConfig config;
  config.lost_frames_keep = 5;
  FollowedBall ball(config);
  Prediction p;
  int i = FollowSixFrames(ball);
  for (int lost = 0; lost <= 3; ++lost, ++i) {
    EXPECT_EQ(ball.Predict(Lob::T(i), &p), lost <= 2) << lost << " frames lost";
    ball.Missed();
  }
  EXPECT_EQ(ball.expected().max_extent_px, 0) << "no prediction: no limit on the box";
  EXPECT_EQ(ball.expected().motion_px, 1e9);
  double x, y;
  EXPECT_TRUE(ball.PredictInFrame(Lob::T(i), &x, &y)) << "the arc still guides re-acquisition";
  EXPECT_NEAR(x, Lob::X(i), 0.01);
  for (int k = 0; k < 2; ++k) ball.Missed();
  EXPECT_FALSE(ball.PredictInFrame(Lob::T(i), &x, &y)) << "lost longer than lost_frames_keep";
  EXPECT_NEAR(ball.radius(), Lob::kR, 1e-6) << "its size is kept";
}

TEST(FollowedBall, ANewBallStartsFromTheFindersRadius) {
  const TrackerConfig config;
  FollowedBall ball(config);
  ball.Found(0, SightingAt(100, 100, 20));
  ball.Restart(12);
  EXPECT_EQ(ball.radius(), 0);
  EXPECT_EQ(ball.FollowedRadius(), 12);
  double x, y;
  EXPECT_FALSE(ball.PredictInFrame(0.1, &x, &y));
  ball.Found(0.1, SightingAt(50, 50, 10));
  EXPECT_EQ(ball.FollowedRadius(), 10);
  ball.Found(0.2, SightingAt(50, 52, 15));
  EXPECT_NEAR(ball.radius(), 11, 1e-6) << "a fifth of each new radius";
}

TEST(FollowedBall, SizeRules) {
  const TrackerConfig config;  // radius_change 0.4, segment.max_box_px 220
  const FollowedBall ball(config);
  EXPECT_TRUE(ball.SizeMatches(13.4, 10));
  EXPECT_FALSE(ball.SizeMatches(15.6, 10));
  EXPECT_TRUE(ball.SizeMatches(1.5, 0.5)) << "1.5 px at least";
  EXPECT_FALSE(ball.IsCloseUp(80));
  EXPECT_TRUE(ball.IsCloseUp(90));
  EXPECT_EQ(ball.SegmentParamsFor(80).max_box_px, config.segment.max_box_px);
  EXPECT_EQ(ball.SegmentParamsFor(120).max_box_px, MaxBallExtentPx(120, 0, 0)) << "the box limit grows with a close-up";
}

}  // namespace
}  // namespace bouncefit
