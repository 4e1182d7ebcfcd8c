// A ball run together with something of its own colour: its shadow on a floor of its hue, seen
// from above (a basketball on parquet). The window's blob is then the ball and the patch at
// once, cut by the window's edge, and its centroid is not the ball's centre.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "tests/tracker_test_util.h"
#include "track/tracker.h"

namespace bouncefit {
namespace {

TEST(TrackerMergedBlob, ASlowBallJoinedByAPatchOfItsColourIsFoundByItsRim) {
  const double ball_bgr[3] = {30, 90, 220};
  const cv::Scalar ball_colour(ball_bgr[0], ball_bgr[1], ball_bgr[2]);
  Tracker tracker(testing::ConfigForColor(ball_bgr, "orange"));
  const double r = 30, y = 180, fps = 30;
  cv::RNG rng(5);
  int joined = 0, found = 0, off = 0;
  double worst = 0;
  for (int i = 0; i < 40; ++i) {
    // Rolling right 2 px a frame; from frame 12 on a flat patch of the ball's colour, wider
    // than the search window, lies against its lower half (a shadow the floor's hue tints).
    const double x = 120 + 2.0 * i;
    cv::Mat img(360, 480, CV_8UC3, cv::Scalar(128, 128, 128));
    const bool patch = i >= 12;
    if (patch)
      cv::ellipse(img, cv::Point2d(x + 0.4 * r, y + 0.85 * r), cv::Size2d(2.6 * r, 0.45 * r), 0, 0, 360,
                  ball_colour, cv::FILLED, cv::LINE_AA);
    testing::DrawBall(img, x, y, r, ball_colour);
    const BallObservation o = tracker.Track(testing::DrawnFrame(img, i, fps, rng));
    if (!patch) continue;
    ++joined;
    if (!o.found) continue;
    ++found;
    const double err = std::hypot(o.cx - x, o.cy - y);
    worst = std::max(worst, err);
    off += err > 0.1 * r;
  }
  // Reported where the ball is, not at the centroid of the ball and the patch together (which
  // lies about a third of a radius lower).
  EXPECT_EQ(found, joined);
  EXPECT_EQ(off, 0) << "worst " << worst << " px";
}

}  // namespace
}  // namespace bouncefit
