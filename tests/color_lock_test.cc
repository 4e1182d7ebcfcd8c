// What the ball is segmented by (track/color_lock.h), on drawn frames (a ball on a plain wall,
// sensor noise): the lock each naming in the config starts, the colour's slow adaptation to
// the ball's and its bounds, and a brightness lock's background model, which keeps a moving
// ball out and lets a still one fade.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "tests/tracker_test_util.h"
#include "track/ball_segmenter.h"
#include "track/color_lock.h"

namespace bouncefit {
namespace {

const cv::Scalar kWall(180, 170, 160), kOrange(40, 110, 230);

Frame BallFrame(double x, double y, double r, const cv::Scalar& ball, const cv::Scalar& wall, int index,
                cv::RNG& rng) {
  cv::Mat img(240, 320, CV_8UC3, wall);
  testing::DrawBall(img, x, y, r, ball);
  return testing::DrawnFrame(img, index, 30, rng);
}

// The blobs `lock` segments in the whole frame.
std::vector<Blob> Blobs(const ColorLock& lock, const Frame& f) {
  YccPlanes planes;
  lock.Planes(f, cv::Rect(0, 0, f.image.cols, f.image.rows), 1, 1.0, &planes);
  cv::Mat mask;
  return SegmentBlobs(planes, lock.color(), SegmenterParams{}, &mask);
}

TEST(ColorLock, EachNamingInTheConfigStartsItsLock) {
  cv::RNG rng(3);
  const Frame orange = BallFrame(160, 120, 20, kOrange, kWall, 0, rng);
  std::string how;
  TrackerConfig automatic;
  ColorLock none(automatic);
  EXPECT_FALSE(none.StartNamed(orange, &how)) << "nothing named: the choice is automatic";
  EXPECT_FALSE(none.valid());

  const double orange_bgr[3] = {40, 110, 230};
  const TrackerConfig given = testing::ConfigForColor(orange_bgr, "orange");
  ColorLock colour(given);
  ASSERT_TRUE(colour.StartNamed(orange, &how));
  EXPECT_EQ(how.rfind("colour orange: ", 0), 0u) << how;
  EXPECT_FALSE(colour.brightness());
  ASSERT_EQ(Blobs(colour, orange).size(), 1u);
  EXPECT_NEAR(Blobs(colour, orange)[0].centroid.x, 160, 0.5);

  TrackerConfig pick;
  pick.has_pick = true, pick.pick_x = 160, pick.pick_y = 120;
  ColorLock picked(pick);
  ASSERT_TRUE(picked.StartNamed(orange, &how));
  EXPECT_EQ(how.rfind("picked pixel 160,120: ", 0), 0u) << how;
  EXPECT_LT(std::hypot(picked.color().nu() - colour.color().nu(), picked.color().nv() - colour.color().nv()),
            colour.color().tolerance()) << "the picked colour is the ball's";

  // A white ball picked: nearly grey, followed by its brightness, brighter than its wall.
  const Frame white = BallFrame(160, 120, 20, cv::Scalar::all(240), kWall, 0, rng);
  ColorLock grey(pick);
  ASSERT_TRUE(grey.StartNamed(white, &how));
  EXPECT_TRUE(grey.brightness());
  EXPECT_NE(how.find("nearly grey:: brightness, brighter than a background model"), std::string::npos) << how;

  pick.pick_x = 1000;
  ColorLock outside(pick);
  EXPECT_THROW(outside.StartNamed(orange, &how), std::invalid_argument);
}

// The ball's colour given as it is under white light; the light turns it redder. Good rims
// move the colour towards the ball's, every 4th one, never further than adapt_max_drift; not
// while the surroundings look like the ball.
TEST(ColorLock, TheColourFollowsTheBallWithinItsBound) {
  const double given[3] = {40, 110, 230};
  const TrackerConfig config = testing::ConfigForColor(given, "orange");
  cv::RNG rng(5);
  const cv::Scalar redder(30, 95, 235);
  auto adapted = [&](const cv::Scalar& wall, int rims) {
    ColorLock lock(config);
    std::string how;
    lock.StartNamed(Frame{}, &how);
    for (int i = 0; i < rims; ++i) {
      const Frame f = BallFrame(160, 120, 20, redder, wall, i, rng);
      YccPlanes planes;
      ExtractYcc(f, cv::Rect(100, 60, 120, 120), 1, 1.0, &planes);
      lock.Adapt(planes, 160, 120, 20);
    }
    return lock.color();
  };
  const ColorModel start = ColorModel::FromBgr(40, 110, 230, config.color);
  const ColorModel ball = ColorModel::FromBgr(30, 95, 235, config.color);
  auto distance = [](const ColorModel& a, const ColorModel& b) { return std::hypot(a.nu() - b.nu(), a.nv() - b.nv()); };
  const ColorModel three = adapted(kWall, 3);
  EXPECT_EQ(three.nu(), start.nu()) << "not before the 4th good rim";
  const ColorModel four = adapted(kWall, 4);
  EXPECT_LT(distance(four, ball), distance(start, ball));
  const ColorModel many = adapted(kWall, 800);
  EXPECT_LE(distance(many, start), config.adapt_max_drift * std::hypot(start.nu(), start.nv()) + 1e-6);
  EXPECT_LT(distance(many, ball), distance(four, ball));
  // Before a wall of the ball's own colour: it does not move.
  const ColorModel before_itself = adapted(redder, 40);
  EXPECT_EQ(before_itself.nu(), start.nu());
  EXPECT_EQ(before_itself.nv(), start.nv());
}

// A white ball on a grey wall, in brightness: it stands out of the background model while it
// moves; held still for longer than luma_still_frames the background takes it in.
TEST(ColorLock, ABrightnessLockKeepsAMovingBallOutOfItsBackgroundAndLetsAStillOneFade) {
  TrackerConfig config;
  config.luma_mode = true;
  cv::RNG rng(7);
  ColorLock lock(config);
  std::string how;
  ASSERT_TRUE(lock.StartNamed(Frame{}, &how));
  EXPECT_EQ(how.rfind("brightness: brightness, brighter than a background model by >= 15 luma", 0), 0u) << how;
  const cv::Scalar grey = cv::Scalar::all(120), white = cv::Scalar::all(220);
  double x = 60;
  int still_frames_seen = 0;
  for (int i = 0; i < 120; ++i) {
    if (i < 40) x += 4;  // moves, then rests
    const Frame f = BallFrame(x, 120, 15, white, grey, i, rng);
    lock.SetFrame(f, 0);
    const std::vector<Blob> blobs = Blobs(lock, f);
    const bool seen = blobs.size() == 1 && std::abs(blobs[0].centroid.x - x) < 1;
    // (The first frames overlap where it was when the background started.)
    if (i > 10 && i < 40) {
      EXPECT_TRUE(seen) << "frame " << i << ": moving";
    }
    if (i >= 40) still_frames_seen += seen;
    BallObservation o;
    o.found = seen;
    if (seen) o.cx = blobs[0].centroid.x, o.cy = blobs[0].centroid.y;
    lock.UpdateBackground(seen, o, 15, x, 120);
  }
  EXPECT_GE(still_frames_seen, config.luma_still_frames) << "kept out while it has just come to rest";
  EXPECT_LT(still_frames_seen, 80 - 10) << "then it fades into the background";
}

TEST(ColorLock, ABallThatStandsOutByLittleLowersTheBrightnessThreshold) {
  const TrackerConfig config;  // luma_contrast_share 0.35, luma_min_scale 0.4, min_contrast_luma 15
  ColorLock lock(config);
  EXPECT_NE(lock.StartBrightness(+1, 26).find(">= 9 luma"), std::string::npos) << "0.35 x 26 of 15";
  EXPECT_NE(lock.StartBrightness(-1, 5).find("darker than a background model by >= 6 luma"), std::string::npos)
      << "no lower than 0.4 of it";
  EXPECT_NE(lock.StartBrightness(0, 100).find(">= 15 luma (clamped at 40)"), std::string::npos);
  EXPECT_TRUE(lock.brightness());
  lock.StartColor(ColorModel::FromBgr(40, 110, 230, config.color));
  EXPECT_FALSE(lock.brightness());
  lock.Drop();
  EXPECT_FALSE(lock.valid());
}

}  // namespace
}  // namespace bouncefit
