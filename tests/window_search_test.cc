// The ball looked for in a window (track/window_search.h), on drawn frames with known centres
// (an orange ball on a plain wall, sensor noise): its sub-pixel centre, the gate and the size
// that keep other blobs out, the prediction's windows over a fall, a streak, a ball the
// frame's border cuts (placed by its rim in view, or its centre unknown; an arm reaching in is
// shapeless), and the look back, which leaves the colour as it is.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>

#include "tests/tracker_parts.h"

namespace bouncefit {
namespace {

const cv::Scalar kWall = testing::kWallBgr, kOrange = testing::kOrangeBgr;

// The parts over 640 x 600 frames.
struct Search : testing::TrackerParts {
  Search() : TrackerParts({640, 600}) {}
};

Frame Drawn(cv::Mat img, int index, cv::RNG& rng) { return testing::DrawnFrame(img, index, 60, rng); }

cv::Mat Wall() { return cv::Mat(600, 640, CV_8UC3, kWall); }

TEST(WindowSearch, FindsTheBallsCentreToAFractionOfAPixelWithinItsGate) {
  Search s;
  cv::RNG rng(1);
  cv::Mat img = Wall();
  testing::DrawBall(img, 300.3, 200.6, 20, kOrange);
  testing::DrawBall(img, 420, 200, 20, kOrange);  // another, outside the gate
  const Frame f = Drawn(img, 0, rng);
  BallObservation o;
  ASSERT_TRUE(s.window.Find(f, {305, 205}, 60, 15, &o));
  EXPECT_NEAR(o.cx, 300.3, 0.2);
  EXPECT_NEAR(o.cy, 200.6, 0.2);
  EXPECT_NEAR(o.radius_px, 20, 1);
  EXPECT_FALSE(s.window.shapeless());
  BallObservation none;
  EXPECT_FALSE(s.window.Find(f, {360, 200}, 30, 10, &none)) << "nothing within the gate";
  EXPECT_FALSE(none.found);
}

TEST(WindowSearch, ABlobOfAnotherSizeIsNotTheBallFollowed) {
  Search s;
  cv::RNG rng(2);
  cv::Mat img = Wall();
  testing::DrawBall(img, 300, 200, 20, kOrange);
  s.ball.Found(0, testing::Sighting(300, 200, 10));  // the ball followed is half as big
  BallObservation o;
  EXPECT_FALSE(s.window.Find(Drawn(img, 1, rng), {300, 200}, 60, 15, &o));
}

// testing::DroppedBall at 60 fps: once followed, the prediction's windows find every frame of
// its fall and bounce.
TEST(WindowSearch, ThePredictionsWindowsFollowAFallAndItsBounce) {
  Search s;
  cv::RNG rng(3);
  testing::DroppedBall truth;
  int found = 0, predicted = 0;
  double worst = 0;
  for (int i = 0; i < 50; ++i, truth.Step()) {
    cv::Mat img = Wall();
    testing::DrawBall(img, truth.x, truth.y, truth.r, kOrange);
    const Frame f = Drawn(img, i, rng);
    const double t = i / truth.kFps;
    BallObservation o;
    Prediction p;
    bool ok = false;
    if (s.ball.Predict(t, &p)) {
      ++predicted;
      ok = s.window.FindNearPrediction(f, p, &o);
    } else {
      ok = s.window.Find(f, {300, 60}, 60, 40, &o);  // the first frame: where it is held
    }
    if (!ok) {
      s.ball.Missed();
      continue;
    }
    ++found;
    worst = std::max(worst, std::hypot(o.cx - truth.x, o.cy - truth.y));
    s.ball.Found(t, o);
  }
  EXPECT_EQ(found, 50);
  EXPECT_EQ(predicted, 49);
  EXPECT_LE(worst, 0.5);
}

// A ball swept over the exposure into a streak 3 radii long, paler than its colour: found by its
// coverage, centred at mid-exposure, with the radius followed.
TEST(WindowSearch, AStreakIsFoundAtItsMiddle) {
  Search s;
  cv::RNG rng(4);
  const BallObservation seen = testing::Sighting(300, 100, 10);
  s.ball.Found(0, seen);
  cv::Mat img = Wall(), acc(img.size(), CV_32FC3, cv::Scalar(0, 0, 0));
  const int subs = 16;
  for (int k = 0; k < subs; ++k) {
    cv::Mat sub = Wall();
    testing::DrawBall(sub, 300, 180 + 40.0 * k / (subs - 1), 10, kOrange);
    cv::accumulate(sub, acc);
  }
  acc.convertTo(img, CV_8UC3, 1.0 / subs);
  BallObservation o;
  ASSERT_TRUE(s.window.FindStreak(Drawn(img, 1, rng), {300, 205}, 60, 20, 40, &o));
  EXPECT_NEAR(o.cx, 300, 0.5);
  EXPECT_NEAR(o.cy, 200, 0.5);
  EXPECT_EQ(o.radius_px, 10);
}

// A ball half out of the frame at its left border: the blob is all there is, and a blob cut
// so shows no shape (an arm reaching in looks the same).
TEST(WindowSearch, ABallTheFramesBorderCutsIsShapeless) {
  Search s;
  cv::RNG rng(5);
  cv::Mat img = Wall();
  img(cv::Rect(0, 190, 40, 20)).setTo(kOrange);  // an arm of the ball's colour from the edge
  const Frame f = Drawn(img, 0, rng);
  const BallObservation seen = testing::Sighting(30, 200, 12);
  s.ball.Found(0, seen);
  BallObservation o;
  ASSERT_TRUE(s.window.Find(f, {30, 200}, 40, 20, &o));
  EXPECT_TRUE(s.window.shapeless());
  EXPECT_TRUE(s.window.CutByRoiBorder(cv::Rect2f(o.x, o.y, o.w, o.h)));
  EXPECT_FALSE(s.window.CutByRoiBorder(cv::Rect2f(100, 100, 20, 20)));
}

// The ball of radius r seen whole in the frame before: its size as the rim fit measures it.
void SeeWhole(Search& s, double r, cv::RNG& rng) {
  cv::Mat img = Wall();
  testing::DrawBall(img, 300, 2 * r, r, kOrange);
  BallObservation o;
  ASSERT_TRUE(s.window.Find(Drawn(img, 0, rng), {300, static_cast<float>(2 * r)}, 2 * r, r, &o));
  s.ball.Found(0, o);
}

// A ball above the frame's top, a third of its diameter in view, its size known from an earlier
// sighting: placed by the rim in view (the frame's straight edge is no rim), a close-up and a
// small ball alike, not at the centroid of the cap the frame shows.
TEST(WindowSearch, ABallTheFramesTopCutsIsPlacedByItsRimInView) {
  for (const double r : {100.0, 20.0}) {
    Search s;
    cv::RNG rng(7);
    cv::Mat img = Wall();
    const double x = 300.4, y = -0.3 * r;
    testing::DrawBall(img, x, y, r, kOrange);
    SeeWhole(s, r, rng);
    BallObservation o;
    ASSERT_TRUE(s.window.Find(Drawn(img, 1, rng), {300, 0}, 2 * r, 2 * r, &o)) << "radius " << r;
    ASSERT_TRUE(CentrePlaced(o)) << "radius " << r;
    EXPECT_NEAR(o.cx, x, 0.3) << "radius " << r;
    EXPECT_NEAR(o.cy, y, 0.5) << "radius " << r;
    EXPECT_NEAR(o.radius_px, r, 0.03 * r) << "radius " << r;
    EXPECT_EQ(o.y, 0);
    EXPECT_FALSE(s.window.shapeless());
  }
}

// Too little of it in view to place: a close-up's cap whose rim spans 83 degrees (a pixel off
// in the radius held to would move its centre a pixel), a small ball's sliver five pixels deep
// (no rim to cast rays on). Found, its box what the frame shows, its centre unknown.
TEST(WindowSearch, TooLittleOfABallTheFramesTopCutsLeavesItsCentreUnknown) {
  for (const auto& [r, y] : {std::pair{100.0, -75.0}, std::pair{20.0, -15.0}}) {
    Search s;
    cv::RNG rng(8);
    cv::Mat img = Wall();
    testing::DrawBall(img, 300, y, r, kOrange);
    SeeWhole(s, r, rng);
    BallObservation o;
    ASSERT_TRUE(s.window.Find(Drawn(img, 1, rng), {300, 0}, 2 * r, 2 * r, &o)) << "radius " << r;
    EXPECT_TRUE(o.found);
    EXPECT_FALSE(CentrePlaced(o)) << "radius " << r << ": centre " << o.cx << ", " << o.cy;
    EXPECT_EQ(o.y, 0);
    EXPECT_NEAR(o.h, r + y, 2) << "radius " << r;
    EXPECT_EQ(o.radius_px, s.ball.last_radius());
  }
}

// The same rims seen in later frames move the colour towards the ball's; seen in earlier
// frames (the look back) they do not.
TEST(WindowSearch, TheLookBackLeavesTheColourAsItIs) {
  Search now, back;
  cv::RNG rng(6);
  const cv::Scalar redder(20, 80, 240);
  const BallObservation seen = testing::Sighting(300, 200, 20);
  now.ball.Found(0, seen);
  back.ball.Found(0, seen);
  const double nu = now.lock.color().nu();
  for (int i = 0; i < 40; ++i) {
    cv::Mat img = Wall();
    testing::DrawBall(img, 300, 200, 20, redder);
    const Frame f = Drawn(img, i, rng);
    BallObservation a, b;
    ASSERT_TRUE(now.window.Find(f, {300, 200}, 50, 20, &a));
    ASSERT_TRUE(back.window.FindInEarlierFrame(f, {300, 200}, 10, 0, &b));
  }
  EXPECT_NE(now.lock.color().nu(), nu);
  EXPECT_EQ(back.lock.color().nu(), nu);
}

}  // namespace
}  // namespace bouncefit
