// The ball (re)acquired over the whole frame (track/whole_frame_search.h), on drawn frames
// (orange balls on a plain wall, sensor noise): found anywhere at its centre, never a still
// lookalike that was there when the ball was chosen, the ball that moved rather than the one
// that did not, and no sliver at the frame's border.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>

#include "tests/tracker_parts.h"

namespace bouncefit {
namespace {

const cv::Scalar kWall = testing::kWallBgr, kOrange = testing::kOrangeBgr;

// The parts over 640 x 480 frames.
struct Search : testing::TrackerParts {
  Search() : TrackerParts({640, 480}) {}
};

// Orange balls of radius 15 at `centres`.
Frame Balls(const std::vector<cv::Point2d>& centres, int index, cv::RNG& rng) {
  cv::Mat img(480, 640, CV_8UC3, kWall);
  for (const cv::Point2d& c : centres) testing::DrawBall(img, c.x, c.y, 15, kOrange);
  return testing::DrawnFrame(img, index, 30, rng);
}

TEST(WholeFrameSearch, FindsTheBallAnywhereAtItsCentre) {
  Search s;
  cv::RNG rng(1);
  for (int i = 0; i < 3; ++i) {
    const cv::Point2d at(80 + 230.3 * i, 400 - 150.6 * i);
    BallObservation o;
    ASSERT_TRUE(s.whole.Acquire(Balls({at}, i, rng), &o)) << i;
    EXPECT_NEAR(o.cx, at.x, 0.2);
    EXPECT_NEAR(o.cy, at.y, 0.2);
  }
  BallObservation none;
  EXPECT_FALSE(s.whole.Acquire(Balls({}, 3, rng), &none));
  EXPECT_EQ(s.whole.acquisitions(), 4);
}

// A still thing of the ball's colour and size, there when the ball was chosen: with the ball
// gone it is not taken for it (a search without that memory takes it) until a new ball is
// chosen.
TEST(WholeFrameSearch, AStillLookalikeFromTheChoiceIsNeverTheBall) {
  Search remembering, fresh;
  cv::RNG rng(2);
  BallCandidate chosen;
  chosen.x = 200, chosen.y = 200, chosen.r = 15;
  remembering.whole.RememberLookalikes(Balls({{200, 200}, {450, 300}}, 0, rng), chosen);
  const Frame gone = Balls({{450, 300}}, 1, rng);
  BallObservation o;
  EXPECT_FALSE(remembering.whole.Acquire(gone, &o));
  ASSERT_TRUE(fresh.whole.Acquire(gone, &o));
  EXPECT_NEAR(o.cx, 450, 0.5);
  remembering.whole.Restart();
  EXPECT_TRUE(remembering.whole.Acquire(gone, &o));
}

TEST(WholeFrameSearch, TheBallThatMovedRatherThanTheOneThatDidNot) {
  Search s;
  cv::RNG rng(3);
  BallObservation o;
  ASSERT_TRUE(s.whole.Acquire(Balls({{200, 200}, {420, 200}}, 0, rng), &o));
  for (const double x : {430.0, 440.0}) {
    ASSERT_TRUE(s.whole.Acquire(Balls({{200, 200}, {x, 200}}, 1, rng), &o));
    EXPECT_NEAR(o.cx, x, 0.5);
  }
}

// The ball followed (radius 15) is lost low; a glint at the top border, shorter than its
// radius, is no cap of it.
TEST(WholeFrameSearch, ASliverAtTheFramesBorderIsNotTheBallFollowed) {
  Search s;
  cv::RNG rng(4);
  const BallObservation seen = testing::Sighting(300, 400, 15);
  s.ball.Found(0, seen);
  cv::Mat img(480, 640, CV_8UC3, kWall);
  img(cv::Rect(300, 0, 12, 5)).setTo(kOrange);
  BallObservation o;
  EXPECT_FALSE(s.whole.Acquire(testing::DrawnFrame(img, 1, 30, rng), &o));
  // A cap as long as its radius is.
  img(cv::Rect(300, 0, 24, 6)).setTo(kOrange);
  EXPECT_TRUE(s.whole.Acquire(testing::DrawnFrame(img, 2, 30, rng), &o));
}

}  // namespace
}  // namespace bouncefit
