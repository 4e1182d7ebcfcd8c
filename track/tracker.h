#pragma once
// Finds the ball in one frame. The capture node and the run command use only this
// interface.
//
// Pipeline (the seed paper's, then better): Gaussian blur -> YCbCr (YUYV frames are read as
// they are) -> optional ROI -> chroma threshold around the ball colour -> blobs with the
// paper's min/max box -> the blob nearest the parabolic prediction -> sub-pixel centre from a
// robust circle fit to the rim. The tracker coordinates its parts, each with its own state:
// - ColorLock (track/color_lock.h): what the ball is segmented by, a colour named, picked or
//   chosen (its threshold adapting), or brightness against a background model;
// - FollowedBall (track/followed_ball.h): the prediction, radius and last sighting, and what
//   a frame may expect of the ball;
// - WindowSearch (track/window_search.h): once locked, the ball looked for in a window round
//   the prediction (or round where it was chosen), as a streak too;
// - WholeFrameSearch (track/whole_frame_search.h): the whole frame at half resolution, only
//   to (re)acquire, with the lookalikes it remembers;
// - AutoChoice (track/auto_choice.h): with no colour named, which candidate is the ball and
//   whether its lock is kept, until its track becomes a ballistic arc;
// - CameraMotion (track/camera_motion.h): a hand-held camera's shift, taken out of the track.
#include <cstdint>
#include <string>

#include "capture/frame.h"
#include "track/auto_choice.h"
#include "track/ball_observation.h"
#include "track/camera_motion.h"
#include "track/color_lock.h"
#include "track/color_model.h"
#include "track/followed_ball.h"
#include "track/tracker_config.h"
#include "track/whole_frame_search.h"
#include "track/window_search.h"

namespace bouncefit {

class Tracker {
 public:
  // Throws std::invalid_argument for an invalid config.
  explicit Tracker(TrackerConfig config);
  // Its parts keep references to each other and to the config.
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  // Frames must come in capture order; the tracker predicts the next position from them.
  // Throws std::invalid_argument for a frame that does not match its PixelFormat or a pick
  // point outside the first frame.
  BallObservation Track(const Frame& frame);
  // One line for the user: what colour it locked on and why.
  std::string Describe() const;

  // The ball followed, looked for again in an earlier frame (track/look_back_tracker.h): near
  // `centre` (pixels), as far as `reach_px` beyond its own radius, as a streak too where it may
  // sweep more than half its radius over the frame (`sweep_px`). Changes nothing the tracker
  // follows. False when not found, or with nothing to look with: no colour chosen yet, or
  // brightness (its background model is of now, not of then).
  // `replaces`: the frame had a sighting of its own (a tentative lock's, or a ball too little in
  // view to place), counted already. cut_radius_px: the ball's radius in the sighting nearest
  // that frame (WindowSearch::FindInEarlierFrame).
  bool FindInEarlierFrame(const Frame& frame, cv::Point2f centre, double reach_px, double sweep_px,
                          BallObservation* obs, bool replaces = false, double cut_radius_px = 0);

  // The last frame's sighting is of an automatic lock not yet confirmed, seen only as a blob
  // running on out of the frame (an arm reaching in from its edge): the ball may be beside it,
  // and a later choice may find it there (the look back waits for it).
  bool tentative() const { return tentative_; }
  bool color_chosen() const { return lock_.valid(); }
  const ColorModel& color() const { return lock_.color(); }
  int64_t acquisitions() const { return whole_frame_.acquisitions(); }

 private:
  // The frame's size sets the ROI; throws std::invalid_argument for a frame too small for it.
  void FitFrameSize(cv::Size size);
  // Nothing locked: the lock the config names, or the automatic choice's.
  bool ChooseColor(const Frame& frame);
  // `c`, a candidate of the automatic choice, becomes the lock.
  void Adopt(const BallCandidate& c);
  // While the automatic lock is not yet confirmed: confirm, replace or drop it.
  void ReviewAutoLock(const Frame& frame, const BallObservation& obs);
  void SetLumaFrame(const Frame& frame);  // the brightness lock's per-frame start

  TrackerConfig config_;
  cv::Rect roi_;
  cv::Size size_;
  std::string how_;
  CameraMotion camera_;
  ColorLock lock_;
  FollowedBall ball_;
  WindowSearch window_;
  WholeFrameSearch whole_frame_;
  AutoChoice auto_;
  int64_t frames_ = 0, found_ = 0;
  int64_t found_earlier_ = 0;  // frames the ball was found in looking back
  bool tentative_ = false;
};

}  // namespace bouncefit
