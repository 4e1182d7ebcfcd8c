#pragma once
// The ball looked for in a window: round the prediction (a tight window first, a wider one
// for a bounce, then as a streak), round where the ball was chosen, round a blob the
// whole-frame search found, or in an earlier frame (the look back). The blob nearest the
// window's centre that can be the ball is refined to a sub-pixel centre by a robust circle
// fit to its rim (track/ball_centre.h); a ball swept into a streak over the exposure is found
// by its coverage (track/ball_streak.h). A rim found well adapts the colour lock.
#include <opencv2/core.hpp>

#include "capture/frame.h"
#include "track/ball_observation.h"
#include "track/ball_segmenter.h"
#include "track/color_lock.h"
#include "track/followed_ball.h"
#include "track/tracker_config.h"
#include "track/ycc_planes.h"

namespace bouncefit {

class WindowSearch {
 public:
  // `roi`: the tracker's region of interest, read at each search (it follows the frame size).
  WindowSearch(const TrackerConfig& config, const cv::Rect& roi, ColorLock& lock, const FollowedBall& ball)
      : config_(config), roi_(roi), lock_(lock), ball_(ball) {}

  // Round the prediction: in flight the parabola predicts to a pixel, a bounce or a kick
  // breaks it.
  bool FindNearPrediction(const Frame& frame, const Prediction& p, BallObservation* obs);
  // In the square window of half-size `half` round `centre`, within the ROI: the blob nearest
  // `centre`, at most `gate` px from it, that can be the ball. recentre: a close-up the
  // window cuts is looked for once more in a window round it.
  bool Find(const Frame& frame, cv::Point2f centre, double half, double gate, BallObservation* obs,
            bool recentre = true);
  // The ball as a streak in that window: its centre at mid-exposure, its size the tracked
  // radius (the streak's length is the sweep, not the ball). sweep_px: the most the ball can
  // move over an exposure.
  bool FindStreak(const Frame& frame, cv::Point2f centre, double half, double gate, double sweep_px,
                  BallObservation* obs);
  // The ball followed, in an earlier frame: near `centre`, as far as `reach_px` beyond its
  // radius, as a streak too where it sweeps more than half its radius (`sweep_px`). The colour
  // does not adapt to it, and its pixels are not taken for the current frame's afterwards.
  // cut_radius_px: the ball's radius in the sighting nearest that frame, which a ball the
  // border cuts there is placed with (0: the radius followed now).
  bool FindInEarlierFrame(const Frame& frame, cv::Point2f centre, double reach_px, double sweep_px,
                          BallObservation* obs, double cut_radius_px = 0);

  bool CutByRoiBorder(const cv::Rect2f& box) const;
  // The last sighting was a blob the frame's (or ROI's) border cuts, with no rim found: all
  // that is known is that it runs on beyond (an arm reaching in), no shape to be a ball by. (A
  // ball the window alone cuts is a streak or a ball run into its shadow: it stays a ball.)
  bool shapeless() const { return shapeless_; }

 private:
  cv::Rect WindowRect(cv::Point2f centre, double half) const;
  // expected: where the window looked for the ball (the prediction, or the blob itself).
  bool Refine(const Frame& frame, const Blob& blob, cv::Point2f expected, BallObservation* obs);
  // A ball the frame's (or ROI's) border cuts, its radius known from its other sightings: placed
  // by the rim in view (track/ball_centre.h, FindCutBallCentre), or found with its centre
  // unknown (NaN) where too little of the rim is in view to place it. False when no round rim
  // of its size shows (the blob is looked at as any other).
  bool RefineCut(const Frame& frame, const Blob& blob, BallObservation* obs);
  // *planes (full resolution) cover the rim rays of a ball of radius r at (x, y).
  void PlanesRound(const Frame& frame, double x, double y, double r, YccPlanes* planes) const;
  // *obs: the blob found as the ball centred at (cx, cy), of radius r.
  void Report(const Blob& blob, double cx, double cy, double r, float score, BallObservation* obs) const;

  const TrackerConfig& config_;
  const cv::Rect& roi_;
  ColorLock& lock_;
  const FollowedBall& ball_;
  YccPlanes planes_;
  YccPlanes cut_planes_;  // RefineCut's
  cv::Mat mask_;
  bool shapeless_ = false;
  bool looking_back_ = false;  // in FindInEarlierFrame: no colour adaptation
  double cut_radius_ = 0;      // ... and the radius a ball the border cuts is placed with (0: followed)
};

}  // namespace bouncefit
