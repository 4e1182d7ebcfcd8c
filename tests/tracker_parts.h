#pragma once
// Shared by the tests of the tracker's searches: its parts wired as the tracker wires them,
// without the tracker, for an orange ball (BGR 40, 110, 230) whose colour is given.
#include <opencv2/core.hpp>

#include <string>

#include "tests/tracker_test_util.h"
#include "track/color_lock.h"
#include "track/followed_ball.h"
#include "track/whole_frame_search.h"
#include "track/window_search.h"

namespace bouncefit::testing {

inline const cv::Scalar kOrangeBgr(40, 110, 230), kWallBgr(180, 170, 160);

inline TrackerConfig OrangeGiven() {
  const double orange[3] = {40, 110, 230};
  return ConfigForColor(orange, "orange");
}

// The ball found at (x, y), radius r, pixels.
inline BallObservation Sighting(double x, double y, double r) {
  BallObservation o;
  o.found = true;
  o.cx = static_cast<float>(x), o.cy = static_cast<float>(y), o.radius_px = static_cast<float>(r);
  return o;
}

// The searches over frames of `size`, the colour locked.
struct TrackerParts {
  explicit TrackerParts(cv::Size size) : roi(0, 0, size.width, size.height) {
    std::string how;
    lock.StartNamed(Frame{}, &how);
  }
  TrackerConfig config = OrangeGiven();
  cv::Rect roi;
  ColorLock lock{config};
  FollowedBall ball{config};
  WindowSearch window{config, roi, lock, ball};
  WholeFrameSearch whole{config, roi, window, lock, ball};
};

}  // namespace bouncefit::testing
