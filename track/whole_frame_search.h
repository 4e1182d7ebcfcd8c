#pragma once
// The ball (re)acquired: the whole frame (the ROI) searched at half resolution for blobs of the
// lock's colour, ranked by colour, shape, size, the prediction and whether they moved, the best
// few tried at full resolution in a window of their own (track/window_search.h). It remembers
// the lookalikes it passed over, and what was already there, of the ball's colour, when the
// ball was chosen: still things of its hue are never taken for it.
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "capture/frame.h"
#include "track/ball_finder.h"
#include "track/ball_observation.h"
#include "track/ball_segmenter.h"
#include "track/color_lock.h"
#include "track/followed_ball.h"
#include "track/tracker_config.h"
#include "track/window_search.h"
#include "track/ycc_planes.h"

namespace bouncefit {

class WholeFrameSearch {
 public:
  // `roi`: the tracker's region of interest, read at each search (it follows the frame size).
  WholeFrameSearch(const TrackerConfig& config, const cv::Rect& roi, WindowSearch& window, const ColorLock& lock,
                   const FollowedBall& ball)
      : config_(config), roi_(roi), window_(window), lock_(lock), ball_(ball) {}

  bool Acquire(const Frame& frame, BallObservation* obs);
  // A new ball chosen: the last one's lookalikes are forgotten.
  void Restart();
  // Remembers every blob of the lock's colour in `frame` away from the ball `chosen` (the
  // frame it was chosen in): still things of its hue.
  void RememberLookalikes(const Frame& frame, const BallCandidate& chosen);
  int64_t acquisitions() const { return acquisitions_; }  // whole-frame searches so far

 private:
  struct Lookalike {
    cv::Point2f p;
    float r;
    bool at_choice = false;  // already there, of the ball's colour, when it was chosen
  };

  const TrackerConfig& config_;
  const cv::Rect& roi_;
  WindowSearch& window_;
  const ColorLock& lock_;
  const FollowedBall& ball_;
  YccPlanes wide_;
  std::vector<Lookalike> lookalikes_;
  std::vector<Blob> last_candidates_;  // the blobs of the last search, to tell which moved
  int64_t acquisitions_ = 0;
};

}  // namespace bouncefit
