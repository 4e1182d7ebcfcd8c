// The tracker's look back (track/look_back_tracker.h) on drawn frames with known centres: an
// orange ball held still, then dropped at 30 fps. The automatic finder sees only what moves,
// so the tracker alone finds the ball a few frames into its fall; looking back from there it
// must find it in the frames before (the hold and the fall's start) at its true centre, let
// every frame out once and in order, keep none waiting while the ball is followed, and let a
// frame without the ball out within its wait.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

#include "tests/tracker_test_util.h"
#include "track/look_back_tracker.h"
#include "track/tracker.h"

namespace bouncefit {
namespace {

constexpr double kFps = 30, kPxPerM = 2000, kG = 9.81 * kPxPerM, kR = 30;
constexpr int kReleaseFrame = 20, kHiddenFrame = 40, kFrames = 60;
constexpr double kHoldY = 100, kFloorY = 560;

// Where the ball's centre is on frame i: held until kReleaseFrame, then falling and bouncing
// (restitution 0.8), pixels.
double CentreY(int i) {
  double y = kHoldY, vy = 0;
  const int sub = 20;
  for (int k = 0; k < (i - kReleaseFrame) * sub; ++k) {
    vy += kG / (kFps * sub);
    y += vy / (kFps * sub);
    if (y + kR > kFloorY && vy > 0) y = 2 * (kFloorY - kR) - y, vy = -0.8 * vy;
  }
  return y;
}

Frame DrawFrame(int i, cv::RNG& rng, bool with_ball = true) {
  cv::Mat img(600, 640, CV_8UC3, cv::Scalar(180, 170, 160));
  if (with_ball) testing::DrawBall(img, 320, CentreY(i), kR, cv::Scalar(40, 110, 230));
  Frame f = testing::DrawnFrame(img, i, kFps, rng);
  f.owns_image = true;
  return f;
}

struct DropRun {
  std::vector<BallObservation> out;  // as they came out
  std::vector<int> waited;           // per frame: frames read after it before it came out
};

DropRun TrackDrop(LookBackConfig config = {}) {
  Tracker tracker{TrackerConfig{}};
  LookBackTracker look_back(tracker, config);
  cv::RNG rng(5);
  DropRun run;
  run.waited.assign(kFrames, -1);
  auto take = [&](const std::vector<TrackedFrame>& settled, int now) {
    for (const TrackedFrame& f : settled) {
      run.out.push_back(f.obs);
      run.waited[static_cast<size_t>(f.obs.frame)] = now - static_cast<int>(f.obs.frame);
    }
  };
  for (int i = 0; i < kFrames; ++i) {
    take(look_back.Track(DrawFrame(i, rng, i != kHiddenFrame)), i);
  }
  take(look_back.Flush(), kFrames);
  return run;
}

// The first frame the tracker finds the ball in without looking back.
int FirstFoundAlone() {
  const DropRun alone = TrackDrop(LookBackConfig{.max_wait_s = 0, .max_frames = 0});
  for (const BallObservation& o : alone.out)
    if (o.found) return static_cast<int>(o.frame);
  return -1;
}

TEST(LookBackTracker, FindsTheHeldBallAndTheFallsStartFromItsFirstSighting) {
  const DropRun run = TrackDrop();
  ASSERT_EQ(run.out.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) EXPECT_EQ(run.out[static_cast<size_t>(i)].frame, i) << "out of order";
  // From a quarter of a second before the first sighting (the longest a frame waits) on, the
  // ball is found in every frame but the one it is missing from, at its centre: the hold's
  // last frames and the fall's first.
  const int first = FirstFoundAlone();
  const int from = first - static_cast<int>(std::floor(0.25 * kFps));
  ASSERT_GT(first, kReleaseFrame);
  ASSERT_LE(from, kReleaseFrame - 3);
  int found = 0;
  double worst = 0;
  for (int i = from; i < kFrames; ++i) {
    const BallObservation& o = run.out[static_cast<size_t>(i)];
    if (i == kHiddenFrame) {
      EXPECT_FALSE(o.found);
      continue;
    }
    EXPECT_TRUE(o.found) << "frame " << i;
    if (!o.found) continue;
    ++found;
    worst = std::max(worst, std::hypot(o.cx - 320, o.cy - CentreY(i)));
  }
  std::printf("first sighting on frame %d (released on %d); found from frame %d on in %d of %d frames, worst "
              "centre %.2f px\n", first, kReleaseFrame, from, found, kFrames - from - 1, worst);
  EXPECT_LT(worst, 1.0);
}

TEST(LookBackTracker, NoFrameWaitsWhileTheBallIsFollowedAndNoneLongerThanItsWait) {
  const DropRun run = TrackDrop();
  // Followed (a third of a second after the release): out with the frame that read it, but for
  // the hidden frame, which waits for the next.
  for (int i = kReleaseFrame + 10; i < kFrames; ++i) {
    if (i == kHiddenFrame) continue;
    EXPECT_EQ(run.waited[static_cast<size_t>(i)], 0) << "frame " << i;
  }
  EXPECT_EQ(run.waited[kHiddenFrame], 1);
  for (int i = 0; i < kFrames; ++i) EXPECT_LE(run.waited[static_cast<size_t>(i)], std::ceil(0.25 * kFps) + 1);
}

TEST(LookBackTracker, WithoutAWaitItIsTheTrackerAlone) {
  const DropRun alone = TrackDrop(LookBackConfig{.max_wait_s = 0, .max_frames = 0});
  for (int w : alone.waited) EXPECT_EQ(w, 0);
  for (int i = 0; i < kFrames; ++i) EXPECT_EQ(alone.out[static_cast<size_t>(i)].frame, i);
}

}  // namespace
}  // namespace bouncefit
