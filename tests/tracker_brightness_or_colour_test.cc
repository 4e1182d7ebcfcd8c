// What the automatic choice follows, and what it takes back after losing the ball.
//
// A white ball under warm light has a faint tint that a black cloth lacks (the shared
// ping-pong clip: 0.22 chroma/luma) and a far larger step of brightness (138 luma): it is
// followed by what sets it apart the most. A ball of a clear colour on the same cloth keeps
// its colour. And a ball just lost at its impact is not taken back as the sliver of something
// bright that the frame's top border cuts (the shared clip, once followed by brightness: a
// patch at the top of its 1750 px frame while the ball bounced at the bottom).
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>

#include "tests/tracker_test_util.h"
#include "track/tracker.h"

namespace bouncefit {
namespace {

struct DropRun {
  int frames_after_choice = 0, found = 0;
  double worst_px = 0;
  int near_top = 0;  // observations within 30 px of the frame's top while the ball is low
  std::string describe;
};

struct DropScene {
  cv::Scalar ball, cloth;
  double r = 30;
  bool sliver = false;  // a bright sliver cut by the top border, moving, from frame 15 on
  // Frames the ball is not drawn on (as a blurred impact hides it): [hide_first, hide_last].
  int hide_first = -1, hide_last = -1;
};

// testing::DroppedBall before a plain cloth, drawn with sub-pixel edges, noise sigma 2.
DropRun TrackDrop(const DropScene& scene) {
  Tracker tracker{TrackerConfig{}};
  testing::DroppedBall ball;
  ball.r = scene.r;
  cv::RNG rng(7);
  DropRun run;
  bool chosen = false;
  for (int i = 0; i < 150; ++i, ball.Step()) {
    cv::Mat img(600, 640, CV_8UC3, scene.cloth);
    const bool hidden = i >= scene.hide_first && i <= scene.hide_last;
    if (!hidden) testing::DrawBall(img, ball.x, ball.y, ball.r, scene.ball);
    if (scene.sliver && i >= 15) testing::DrawBall(img, 100 + 2.0 * i, -14, 20, scene.ball);
    const BallObservation o = tracker.Track(testing::DrawnFrame(img, i, ball.kFps, rng));
    chosen = chosen || o.found;
    if (chosen && !hidden) {
      ++run.frames_after_choice;
      if (o.found) {
        ++run.found;
        run.worst_px = std::max(run.worst_px, std::hypot(o.cx - ball.x, o.cy - ball.y));
      }
    }
    if (o.found && o.cy < 30 && ball.y > 200) ++run.near_top;  // the sliver taken for the ball
  }
  run.describe = tracker.Describe();
  std::printf("found %d of %d frames after the choice (hidden ones aside), worst %.2f px, %d at the top\n%s\n",
              run.found, run.frames_after_choice, run.worst_px, run.near_top, run.describe.c_str());
  return run;
}

// BGR 140,200,250 before 20,20,22: about 0.2 chroma/luma of tint, 190 luma brighter.
const cv::Scalar kWarmWhite(140, 200, 250), kBlackCloth(20, 20, 22);

TEST(TrackerBrightnessOrColour, ATintedWhiteBallOnBlackIsFollowedByItsBrightness) {
  const DropRun run = TrackDrop({kWarmWhite, kBlackCloth});
  EXPECT_NE(run.describe.find("brightness"), std::string::npos) << run.describe;
  EXPECT_NE(run.describe.find("ballistic"), std::string::npos) << run.describe;
  EXPECT_GE(run.found, run.frames_after_choice - 4);
  EXPECT_LE(run.worst_px, 1.0);
}

TEST(TrackerBrightnessOrColour, AnOrangeBallOnBlackKeepsItsColour) {
  // 125 luma brighter and 0.64 chroma/luma of colour: about as strong, colour it is.
  const DropRun run = TrackDrop({cv::Scalar(30, 120, 240), kBlackCloth});
  EXPECT_NE(run.describe.find("its colour"), std::string::npos) << run.describe;
  EXPECT_GE(run.found, run.frames_after_choice - 4);
  EXPECT_LE(run.worst_px, 1.0);
}

TEST(TrackerBrightnessOrColour, ABallLostLowIsNotTakenBackAsASliverAtTheTop) {
  DropScene scene{kWarmWhite, kBlackCloth};
  scene.sliver = true;
  scene.hide_first = 22, scene.hide_last = 25;  // the ball hidden at its first impact
  const DropRun run = TrackDrop(scene);
  EXPECT_EQ(run.near_top, 0);
  EXPECT_GE(run.found, run.frames_after_choice - 6);
  EXPECT_LE(run.worst_px, 1.0);
}

}  // namespace
}  // namespace bouncefit
