// The tracker's part of the look back (track/look_back_tracker.h): the ball it follows now,
// looked for in an earlier frame without touching what it follows.
#include "track/tracker.h"

namespace bouncefit {

bool Tracker::FindInEarlierFrame(const Frame& frame, cv::Point2f centre, double reach_px, double sweep_px,
                                 BallObservation* obs, bool replaces) {
  if (!color_.valid() || luma_ || radius_ <= 0 || frame.image.size() != size_) return false;
  // What the search of the frame being tracked set for itself: no prediction here, no box
  // limit from its speed.
  const double extent = max_extent_px_, motion = expected_motion_px_;
  max_extent_px_ = 0;
  expected_motion_px_ = 1e9;
  looking_back_ = true;
  const double half = 1.6 * radius_ + config_.window_margin_px + reach_px;
  const double gate = 0.5 * radius_ + config_.gate_px + reach_px;
  bool ok = TryWindow(frame, centre, half, gate, obs);
  if (!ok && sweep_px > 0.5 * radius_) ok = TryStreak(frame, centre, half, gate, sweep_px, obs);
  looking_back_ = false;
  max_extent_px_ = extent;
  expected_motion_px_ = motion;
  planes_.rect = cv::Rect();  // an earlier frame's pixels: never taken for this one's
  if (ok && replaces) --found_;
  if (ok) ++found_earlier_;
  return ok;
}

}  // namespace bouncefit
