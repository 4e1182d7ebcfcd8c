#include "track/followed_ball.h"

#include <algorithm>
#include <cmath>

#include "track/ball_extent.h"

namespace bouncefit {

FollowedBall::FollowedBall(const TrackerConfig& config) : config_(config), predictor_(config.motion) {}

bool FollowedBall::Predict(double t, Prediction* p) {
  expected_ = {};  // no prediction: nothing expected
  if (last_frame_t_ >= 0 && t > last_frame_t_) frame_dt_s_ = t - last_frame_t_;
  last_frame_t_ = t;
  double px, py, speed;
  if (lost_ > 2 || !PredictInFrame(t, &px, &py, &speed)) return false;
  // An arc just begun (an impact, a kick) has no speed of its own yet: the ball leaves it
  // at most as fast as it came.
  double ax = 0, ay = 0;
  if (predictor_.samples() >= 3 && PredictInFrame(t + 1e-3, &ax, &ay) && speed > 0)
    arc_speed_px_s_ = speed, arc_dir_x_ = (ax - px) / (1e-3 * speed), arc_dir_y_ = (ay - py) / (1e-3 * speed);
  else
    speed = std::max(speed, arc_speed_px_s_);
  const double dt = std::clamp(t - last_t_, 1e-3, 0.1);
  const double motion = speed * dt;
  const double frame_dt = frame_dt_s_ > 0 ? frame_dt_s_ : dt;
  expected_.max_extent_px = radius_ > 0 ? MaxBallExtentPx(radius_, speed, frame_dt) : 0;
  expected_.motion_px = motion;
  p->at = cv::Point2f(static_cast<float>(px), static_cast<float>(py));
  p->motion_px = motion;
  p->sweep_px = speed * frame_dt;
  return true;
}

void FollowedBall::Found(double t, const BallObservation& obs) {
  // Seen, too little of it in view to place: the prediction goes on from the last centre.
  if (!CentrePlaced(obs)) {
    lost_ = 0;
    return;
  }
  predictor_.Add(t, obs.cx - shift_x_, obs.cy - shift_y_);
  radius_ = radius_ > 0 ? 0.8 * radius_ + 0.2 * obs.radius_px : obs.radius_px;
  last_radius_ = obs.radius_px;
  lost_ = 0;
  last_t_ = t;
  last_x_ = obs.cx, last_y_ = obs.cy;
}

void FollowedBall::Missed() {
  ++lost_;
  if (lost_ > config_.lost_frames_keep) predictor_.Reset(), arc_speed_px_s_ = 0;
}

void FollowedBall::Forget() {
  predictor_.Reset();
  arc_speed_px_s_ = 0;
  lost_ = 1 << 20;
}

void FollowedBall::Restart(double chosen_r) {
  Forget();
  radius_ = last_radius_ = 0;
  chosen_r_ = chosen_r;
}

bool FollowedBall::PredictInFrame(double t, double* x, double* y, double* speed) const {
  if (!predictor_.Predict(t, x, y, speed)) return false;
  *x += shift_x_, *y += shift_y_;
  return true;
}

cv::Rect2d FollowedBall::WhereBallMayBe(double t) const {
  if (radius_ <= 0 || lost_ > 2) return {};
  // From where it was last seen to where it is predicted: a fast ball crosses tiles a frame.
  double px = last_x_, py = last_y_;
  PredictInFrame(t, &px, &py);
  const double m = 1.5 * radius_ + 8;
  return cv::Rect2d(std::min(px, last_x_) - m, std::min(py, last_y_) - m, std::abs(px - last_x_) + 2 * m,
                    std::abs(py - last_y_) + 2 * m);
}

bool FollowedBall::SizeMatches(double r, double ref_r) const {
  return std::abs(r - ref_r) <= config_.radius_change * ref_r + 1.5;
}

bool FollowedBall::IsCloseUp(double radius_px) const {
  // 2.6 radii: a ball's box once smeared by its motion.
  return 2.6 * radius_px > config_.segment.max_box_px;
}

SegmenterParams FollowedBall::SegmentParamsFor(double radius_px, cv::Rect picture) const {
  // A close-up ball outgrows the configured box limit: the limit grows with the ball followed.
  SegmenterParams p = config_.segment;
  // Lines on the ball are as wide as a share of its diameter.
  if (radius_px > 0) p.join_gap_px = config_.max_line_share * 2 * radius_px;
  p.join_inside = picture;
  if (IsCloseUp(radius_px))
    p.max_box_px = std::max(p.max_box_px, std::max(expected_.max_extent_px, MaxBallExtentPx(radius_px, 0, 0)));
  return p;
}

}  // namespace bouncefit
