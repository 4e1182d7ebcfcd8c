// Pictures a file shows twice (replay/repeated_frames.h), as a re-encoded phone file has
// them: each repeat requantised anew, so a few tens of cells differ by a few levels.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "replay/repeated_frames.h"

namespace bouncefit {
namespace {

// A ball (radius 12 px) crossing a flat 640x480 picture, 6 px a picture.
cv::Mat Scene(int i) {
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(150, 160, 170));
  cv::circle(img, cv::Point(60 + 6 * i, 100 + 4 * i), 12, cv::Scalar(250, 250, 250), cv::FILLED);
  return img;
}

// The picture as an encoder gives it again: `cells` 2x2 blocks `levels` brighter.
cv::Mat Requantised(cv::Mat img, int cells, int levels, cv::RNG& rng) {
  for (int k = 0; k < cells; ++k) {
    const int x = 2 * rng.uniform(0, img.cols / 2), y = 2 * rng.uniform(0, img.rows / 2);
    img(cv::Rect(x, y, 2, 2)) += cv::Scalar::all(levels);
  }
  return img;
}

TEST(RepeatedFrames, ARepeatRequantisedByAnotherEncoderIsStillARepeat) {
  cv::RNG rng(3);
  RepeatedFrameFilter filter;
  int repeats_seen = 0, new_ones_taken = 0;
  for (int i = 0; i < 30; ++i) {
    const cv::Mat picture = Requantised(Scene(i), 30, 6, rng);
    new_ones_taken += filter.IsRepeat(picture);
    // Its repeat: 30 cells (1/2560 of the picture) a few levels off, nothing moved.
    repeats_seen += filter.IsRepeat(Requantised(picture.clone(), 30, 6, rng));
  }
  EXPECT_EQ(new_ones_taken, 0);
  EXPECT_GE(repeats_seen, 27);  // the first two or three make the pattern
  EXPECT_EQ(filter.repeats(), repeats_seen);
}

TEST(RepeatedFrames, PicturesThatDifferByMoreThanARequantisationAreNew) {
  cv::RNG rng(4);
  RepeatedFrameFilter filter;
  int taken = 0;
  for (int i = 0; i < 30; ++i) {
    const cv::Mat picture = Requantised(Scene(i), 30, 6, rng);
    taken += filter.IsRepeat(picture);
    // Not a repeat: 400 cells changed (a tenth of a percent more than a re-encoding leaves).
    taken += filter.IsRepeat(Requantised(picture.clone(), 400, 6, rng));
  }
  EXPECT_EQ(taken, 0);
}

}  // namespace
}  // namespace bouncefit
