#pragma once
// What the tracker knows of the ball it follows: its parabolic prediction (in the scene: a
// held camera's shift taken out), its radius, where and when it was last seen, and what that
// lets a frame expect of it (where it is, how far it moved, how long its box may be). The
// rules on the ball's size (the same ball, a close-up) are here too: every part asks them.
#include <opencv2/core.hpp>

#include <cstdint>

#include "track/ball_observation.h"
#include "track/ball_segmenter.h"
#include "track/motion_predictor.h"
#include "track/tracker_config.h"

namespace bouncefit {

// What a frame's search may expect of the ball.
struct FrameExpectation {
  // The longest box side the ball can show (track/ball_extent.h; 0: no prediction, not checked).
  double max_extent_px = 0;
  double motion_px = 1e9;  // the prediction's motion since the last sighting, px (1e9: none)
};

// Where the prediction puts the ball in a frame.
struct Prediction {
  cv::Point2f at;         // where the frame shows it, pixels
  double motion_px = 0;   // how far it moved since the last sighting
  double sweep_px = 0;    // how far it may move over a frame period (while exposed)
};

class FollowedBall {
 public:
  explicit FollowedBall(const TrackerConfig& config);

  // This frame's camera motion (CameraMotion::dx, dy), pixels.
  void SetCameraShift(double dx, double dy) { shift_x_ = dx, shift_y_ = dy; }
  // Starts the frame at time t (s): sets its expectation; true with *p when the ball was seen
  // in one of the last two frames and the predictor has its arc.
  bool Predict(double t, Prediction* p);
  // A sighting whose centre is unknown (CentrePlaced) keeps the ball followed and adds nothing.
  void Found(double t, const BallObservation& obs);
  void Missed();
  // The lock given up: no prediction, long lost.
  void Forget();
  // A new ball chosen: nothing known of it but the finder's radius, `chosen_r` (px).
  void Restart(double chosen_r);

  double radius() const { return radius_; }  // tracked, pixels (0: unknown)
  // The last sighting's radius, pixels (0: none): a ball moving towards the camera or away
  // changes size faster than the tracked radius follows.
  double last_radius() const { return last_radius_; }
  double FollowedRadius() const { return radius_ > 0 ? radius_ : chosen_r_; }
  int64_t lost() const { return lost_; }       // frames since last found
  double last_x() const { return last_x_; }    // the last centre found, pixels
  double last_y() const { return last_y_; }
  double shift_x() const { return shift_x_; }  // this frame's camera motion, pixels
  double shift_y() const { return shift_y_; }
  // The prediction's speed on the last arc it knew (px/s; 0: none) and its direction (unit).
  double arc_speed_px_s() const { return arc_speed_px_s_; }
  double arc_dir_x() const { return arc_dir_x_; }
  double arc_dir_y() const { return arc_dir_y_; }
  const FrameExpectation& expected() const { return expected_; }
  void set_expected(const FrameExpectation& e) { expected_ = e; }

  // The predictor's position at t (in the scene) where this frame shows it.
  bool PredictInFrame(double t, double* x, double* y, double* speed = nullptr) const;
  // The part of the frame the ball may be in at time t (empty when none is followed).
  cv::Rect2d WhereBallMayBe(double t) const;

  // A radius r (px) is the ball's of radius ref_r: within radius_change of it, and 1.5 px.
  bool SizeMatches(double r, double ref_r) const;
  // A close-up ball: one whose smeared box outgrows the segmenter's box limit (radius 85 px
  // and more with the default 220 px). Its box limit and, in brightness mode, the width of
  // the light changes removed grow with it.
  bool IsCloseUp(double radius_px) const;
  // The segmenter's limits for a ball of radius_px in a picture whose region (its ROI) is
  // `picture` (frame px; empty: not given).
  SegmenterParams SegmentParamsFor(double radius_px, cv::Rect picture = {}) const;

 private:
  const TrackerConfig& config_;
  MotionPredictor predictor_;
  double shift_x_ = 0, shift_y_ = 0;
  double radius_ = 0;
  double last_radius_ = 0;
  double chosen_r_ = 0;      // the finder's radius of a ball just chosen, until it is seen
  int64_t lost_ = 1 << 20;
  double last_t_ = 0;        // s
  double last_x_ = 0, last_y_ = 0;
  FrameExpectation expected_;
  double arc_speed_px_s_ = 0;
  double arc_dir_x_ = 0, arc_dir_y_ = 0;
  double last_frame_t_ = -1, frame_dt_s_ = 0;  // the frame period, s, from the last two frames (-1: none yet)
};

}  // namespace bouncefit
