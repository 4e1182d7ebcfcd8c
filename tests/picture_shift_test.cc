// A hand-held camera's shift between two frames (track/picture_shift.h): the picture's, not
// the ball's.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "track/picture_shift.h"

namespace bouncefit {
namespace {

// A textured scene (smoothed noise, luma 40-215) as YCrCb, 320x240.
cv::Mat TexturedScene() {
  cv::Mat noise(240, 320, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, noise, {0, 0}, 2.0);
  cv::normalize(noise, noise, 40, 215, cv::NORM_MINMAX);
  cv::Mat bgr;
  cv::cvtColor(noise, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

cv::Mat Ycc(const cv::Mat& bgr) {
  cv::Mat ycc;
  cv::cvtColor(bgr, ycc, cv::COLOR_BGR2YCrCb);
  return ycc;
}

cv::Mat Shifted(const cv::Mat& img, int dx, int dy) {
  cv::Mat out;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(img, out, m, img.size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
  return out;
}

cv::Mat WithBall(cv::Mat img, cv::Point at) {
  cv::circle(img, at, 20, cv::Scalar(30, 90, 230), cv::FILLED, cv::LINE_AA);
  return img;
}

PictureShift Measure(const cv::Mat& a, const cv::Mat& b) {
  return MeasurePictureShift(ProfilesOf(Ycc(a)), ProfilesOf(Ycc(b)));
}

TEST(PictureShift, AMovedCameraMovesEveryTexturedTileAlike) {
  const cv::Mat scene = TexturedScene();
  for (const auto& [dx, dy] : {std::pair{3, -2}, std::pair{-1, 0}, std::pair{0, 4}, std::pair{-5, 5}}) {
    const PictureShift s = Measure(scene, Shifted(scene, dx, dy));
    EXPECT_EQ(s.dx, dx) << dx << "," << dy;
    EXPECT_EQ(s.dy, dy) << dx << "," << dy;
    EXPECT_GE(s.agreeing, 24) << "of " << s.informative;
  }
  // With a ball that falls 12 px between them, as a camera shaking while the ball drops.
  const PictureShift s = Measure(WithBall(scene.clone(), {100, 80}),
                                 WithBall(Shifted(scene, 2, 1), {102, 93}));
  EXPECT_EQ(s.dx, 2);
  EXPECT_EQ(s.dy, 1);
}

TEST(PictureShift, ABallMovingBeforeAStillCameraIsNoShift) {
  const cv::Mat scene = TexturedScene();
  const PictureShift s = Measure(WithBall(scene.clone(), {100, 80}), WithBall(scene.clone(), {104, 92}));
  EXPECT_FALSE(s.moved()) << s.dx << "," << s.dy;
  EXPECT_GE(s.agreeing, 24);  // the tiles told, and told 0
  // Before a blank wall the ball is all there is to match: no tile agrees enough to say.
  const cv::Mat blank(240, 320, CV_8UC3, cv::Scalar(120, 120, 120));
  const PictureShift b = Measure(WithBall(blank.clone(), {100, 80}), WithBall(blank.clone(), {104, 92}));
  EXPECT_FALSE(b.moved()) << b.dx << "," << b.dy;
}


// Each tile's profiles are its luma sums divided by the tile's other side, mean removed:
// checked against that definition, written plainly, on any bytes and on widths that leave
// every tile a tail of pixels beside whole blocks of 16.
TEST(PictureShift, ProfilesAreTheTilesLumaMeansAlongEachAxis) {
  cv::RNG rng(11);
  for (const cv::Size size : {cv::Size(4 * 37 + 3, 4 * 29 + 1), cv::Size(320, 240), cv::Size(4 * 16, 8)}) {
    cv::Mat ycc(size, CV_8UC3);
    rng.fill(ycc, cv::RNG::UNIFORM, 0, 256);
    const PictureProfiles got = ProfilesOf(ycc);
    const int t = PictureShiftParams{}.tiles;
    ASSERT_EQ(got.columns.size(), static_cast<size_t>(t * t));
    for (int k = 0; k < t * t; ++k) {
      const cv::Rect r((k % t) * size.width / t, (k / t) * size.height / t, size.width / t, size.height / t);
      std::vector<float> cols(r.width), rows(r.height);
      for (int j = 0; j < r.height; ++j)
        for (int i = 0; i < r.width; ++i) {
          const int y = ycc.at<cv::Vec3b>(r.y + j, r.x + i)[0];
          cols[i] += static_cast<float>(y), rows[j] += static_cast<float>(y);
        }
      for (auto* p : {&cols, &rows}) {
        const float n = static_cast<float>(p == &cols ? r.height : r.width);
        float mean = 0;
        for (float& v : *p) v /= n, mean += v;
        mean /= static_cast<float>(p->size());
        for (float& v : *p) v -= mean;
      }
      EXPECT_EQ(got.columns[k], cols) << size << " tile " << k;
      EXPECT_EQ(got.rows[k], rows) << size << " tile " << k;
    }
  }
}

}  // namespace
}  // namespace bouncefit
