#pragma once
// A ball swept over the exposure: a streak. Where the ball moves more than about its radius
// during the exposure, no pixel is ball for the whole exposure: each is a mix of ball and
// background in the share of the exposure the ball covered it (a ping-pong ball at 4 m/s and
// 1/60 s covers the middle of its streak about half the time), too pale for the ball's colour.
// The streak is found by that share instead: a pixel's chroma along the ball's hue, as a part
// of the ball's own. Its centre is the coverage-weighted centroid, the ball's position at
// mid-exposure (a streak is symmetric about it); across the motion the coverage's spread is
// the ball's own (a quarter of the radius squared, however long the streak), along it the
// diameter plus the sweep.
#include <opencv2/core.hpp>

#include "track/color_model.h"
#include "track/ycc_planes.h"

namespace bouncefit {

struct StreakParams {
  double min_share = 0.2;   // least share of the ball's chroma along its hue that counts as covered
  double min_peak = 0.35;   // the streak's most covered pixels reach at least this share
  double max_off_hue = 0.6; // chroma off the ball's hue, in its tolerances, a covered pixel may have
};

struct BallStreak {
  bool ok = false;
  double cx = 0, cy = 0;       // coverage-weighted centre, frame pixels
  double width_px = 0;         // across the motion: the ball's diameter
  double length_px = 0;        // along it: the diameter plus the sweep over the exposure
  double dir_x = 1, dir_y = 0; // the streak's long axis (unit)
  cv::Rect2f box;              // of its covered pixels, frame pixels
  int pixels = 0;              // covered pixels
};

// The streak in `planes` (full resolution) nearest `expected` (within `gate_px` of its
// centre), for a ball of `color` and about `radius_px`, at most `max_length_px` long. Not ok
// when none is there, or it is not a ball's width across or runs on past that length.
BallStreak FindBallStreak(const YccPlanes& planes, const ColorModel& color, cv::Point2f expected,
                          double gate_px, double radius_px, double max_length_px,
                          const StreakParams& params = {});

}  // namespace bouncefit
