// A camera held in a hand (track/camera_motion.h): a textured scene seen through a window
// that jitters and sways by known sub-pixel amounts, a bright ball falling through it and a
// hand moving in one corner. The measured motion must follow the truth to a tenth of a pixel;
// a still camera must read exactly zero whatever moves in front of it.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "track/camera_motion.h"

namespace bouncefit {
namespace {

constexpr int kW = 640, kH = 480, kMargin = 24;

// A wall with texture at several scales (blurred noise, a few panels and stripes), larger
// than the frame by kMargin each side.
cv::Mat Scene() {
  cv::Mat noise(kH + 2 * kMargin, kW + 2 * kMargin, CV_32F);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0, 30);
  cv::GaussianBlur(noise, noise, cv::Size(), 3);
  cv::Mat scene;
  noise.convertTo(scene, CV_8U, 1, 120);
  for (int k = 0; k < 12; ++k) {
    const cv::Point a(rng.uniform(0, scene.cols), rng.uniform(0, scene.rows));
    cv::rectangle(scene, cv::Rect(a, cv::Size(rng.uniform(20, 120), rng.uniform(20, 120))),
                  cv::Scalar(rng.uniform(60, 200)), cv::FILLED);
  }
  cv::Mat bgr;
  cv::cvtColor(scene, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

struct Shot {
  Frame frame;
  cv::Point2d camera;  // truth: what the first frame showed at p is at p + camera
  cv::Rect2d ball;     // where the ball is, as the tracker would say
};

// Frame i of a clip: the scene moved by `camera`, a ball falling down the middle, a hand
// (a dark block) moving in the top-left corner, sensor noise.
Shot Render(const cv::Mat& scene, int i, cv::Point2d camera, cv::RNG& rng) {
  Shot s;
  s.camera = camera;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, camera.x - kMargin, 0, 1, camera.y - kMargin);
  cv::Mat img;
  cv::warpAffine(scene, img, m, cv::Size(kW, kH), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  const cv::Point2d ball(330 + camera.x, 40 + 3.0 * i + camera.y);
  cv::circle(img, cv::Point(static_cast<int>(ball.x), static_cast<int>(ball.y)), 14,
             cv::Scalar(250, 250, 250), cv::FILLED, cv::LINE_AA);
  s.ball = cv::Rect2d(ball.x - 30, ball.y - 30, 60, 60);
  cv::rectangle(img, cv::Rect(40 + (i % 20) * 4, 30, 60, 90), cv::Scalar(40, 50, 60), cv::FILLED);
  cv::Mat n(img.size(), CV_16SC3);
  rng.fill(n, cv::RNG::NORMAL, 0, 2);
  cv::Mat img16;
  img.convertTo(img16, CV_16SC3);
  img16 += n;
  img16.convertTo(s.frame.image, CV_8UC3);
  s.frame.index = i;
  return s;
}

TEST(CameraMotion, FollowsAHeldCameraToATenthOfAPixel) {
  const cv::Mat scene = Scene();
  cv::RNG rng(3);
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> jitter(-4, 4);
  CameraMotion camera;
  cv::Point2d first;
  double sum2 = 0, worst = 0;
  int n = 0;
  for (int i = 0; i < 120; ++i) {
    // A jitter of up to 4 px a frame and a sway of 6 px at 0.7 Hz (30 fps).
    const double w = 2 * M_PI * 0.7 * i / 30;
    const cv::Point2d raw(jitter(gen) + 6 * std::sin(w), jitter(gen) + 6 * std::cos(w));
    if (i == 0) first = raw;
    const Shot s = Render(scene, i, raw - first, rng);
    camera.Update(s.frame, s.ball);
    if (i < 12) continue;  // reported once several of the frames measured (every third) moved
    ASSERT_TRUE(camera.moving()) << "frame " << i;
    const double ex = camera.dx() - s.camera.x, ey = camera.dy() - s.camera.y;
    sum2 += ex * ex + ey * ey, ++n;
    worst = std::max({worst, std::abs(ex), std::abs(ey)});
  }
  const double rms = std::sqrt(sum2 / (2 * n));
  std::printf("held camera: error %.3f px RMS, %.3f px at worst, %ld frames not measured\n", rms, worst,
              camera.unmeasured());
  EXPECT_LT(rms, 0.08);
  EXPECT_LT(worst, 0.25);
}

TEST(CameraMotion, AStillCameraReadsExactlyZeroWhateverMovesBeforeIt) {
  const cv::Mat scene = Scene();
  cv::RNG rng(5);
  CameraMotion camera;
  for (int i = 0; i < 120; ++i) {
    // The ball is not named to it: only the hand, the ball and the noise move.
    const Shot s = Render(scene, i, {0, 0}, rng);
    camera.Update(s.frame);
    ASSERT_EQ(camera.dx(), 0.0) << "frame " << i;
    ASSERT_EQ(camera.dy(), 0.0) << "frame " << i;
  }
  EXPECT_FALSE(camera.moving());
}

TEST(CameraMotion, MeasuresAWholeShiftBetweenTwoPictures) {
  const cv::Mat scene = Scene();
  cv::RNG rng(9);
  const Shot a = Render(scene, 0, {0, 0}, rng), b = Render(scene, 0, {7, -3}, rng);
  const PictureMotion m = MeasurePictureMotion(CameraProfilesOf(a.frame), CameraProfilesOf(b.frame));
  ASSERT_TRUE(m.x.ok && m.y.ok);
  EXPECT_NEAR(m.x.bins * CameraProfilesOf(a.frame).bin, 7, 0.1);
  EXPECT_NEAR(m.y.bins * CameraProfilesOf(a.frame).bin, -3, 0.1);
}

// A file stored turned gives its luma as it lies: its profiles, summed that way and read
// back turned, are the upright luma's to the last bit, for every turn and sizes no tile grid
// divides; a 16-235 plane's steps are scaled to full range.
TEST(CameraMotion, ProfilesOfAStoredTurnedLumaAreTheUprightOnes) {
  cv::Mat upright(203, 331, CV_8U);
  cv::RNG rng(11);
  rng.fill(upright, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(upright, upright, cv::Size(), 1.5);
  Frame frame;
  cv::cvtColor(upright, frame.image, cv::COLOR_GRAY2BGR);
  const cv::Rect2d ball(100, 40, 30, 30);
  const CameraProfiles expect = CameraProfilesOf(frame, {}, ball, &upright);
  ASSERT_FALSE(expect.empty());
  for (int turn : {90, 180, 270}) {
    // Stored so that turning it `turn` clockwise gives the upright picture.
    cv::Mat stored;
    cv::rotate(upright, stored, turn == 90 ? cv::ROTATE_90_COUNTERCLOCKWISE
                                : turn == 180 ? cv::ROTATE_180 : cv::ROTATE_90_CLOCKWISE);
    const CameraProfiles got = CameraProfilesOf(frame, {}, ball, &stored, 1.0, turn);
    ASSERT_EQ(got.columns.size(), expect.columns.size()) << turn;
    for (size_t k = 0; k < expect.columns.size(); ++k) {
      ASSERT_EQ(got.columns[k].size(), expect.columns[k].size()) << turn;
      ASSERT_EQ(got.rows[k].size(), expect.rows[k].size()) << turn;
      for (size_t i = 0; i < expect.columns[k].size(); ++i)
        if (!std::isnan(expect.columns[k][i])) EXPECT_EQ(got.columns[k][i], expect.columns[k][i]) << turn << " tile " << k << " column " << i;
        else EXPECT_TRUE(std::isnan(got.columns[k][i]));
      for (size_t i = 0; i < expect.rows[k].size(); ++i)
        if (!std::isnan(expect.rows[k][i])) EXPECT_EQ(got.rows[k][i], expect.rows[k][i]) << turn << " tile " << k << " row " << i;
        else EXPECT_TRUE(std::isnan(got.rows[k][i]));
    }
  }
  // The same picture in 16-235: the same steps, within the 8-bit rounding of the squeeze.
  cv::Mat limited;
  upright.convertTo(limited, CV_8U, 219.0 / 255.0, 16);
  const CameraProfiles scaled = CameraProfilesOf(frame, {}, ball, &limited, 255.0 / 219.0);
  double worst = 0;
  for (size_t k = 0; k < expect.columns.size(); ++k)
    for (size_t i = 0; i < expect.columns[k].size(); ++i)
      if (!std::isnan(expect.columns[k][i])) worst = std::max(worst, std::abs(double(scaled.columns[k][i]) - expect.columns[k][i]));
  EXPECT_LT(worst, 0.1) << "luma steps, full range";
}

}  // namespace
}  // namespace bouncefit
