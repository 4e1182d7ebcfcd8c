#pragma once
// The automatic choice of the ball: which candidate of the finder (track/ball_finder.h) is
// locked on, and whether the lock is kept. A lock is reviewed every frame until its track
// becomes a ballistic arc (track/arc_check.h), which confirms it. Until then a better
// candidate elsewhere replaces a lock that stands still or shows no shape, the same ball with
// a colour of its own replaces its brightness lock, and a lock that moves without an arc, or
// is not seen, is dropped (and not chosen again for a while). It decides; the tracker starts
// or ends the lock.
#include <opencv2/core.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "capture/frame.h"
#include "track/arc_check.h"
#include "track/ball_finder.h"
#include "track/ball_observation.h"
#include "track/followed_ball.h"
#include "track/tracker_config.h"

namespace bouncefit {

// What a review of the unconfirmed lock decided.
struct LockReview {
  enum class Verdict {
    kKeep,       // still unconfirmed
    kConfirmed,  // its track became a ballistic arc
    kSwitch,     // `next` replaces it
    kDrop,       // given up: nothing locked
  };
  Verdict verdict = Verdict::kKeep;
  BallCandidate next;
  std::string what;  // kConfirmed: what to add to the description; kDrop: the description
};

class AutoChoice {
 public:
  explicit AutoChoice(const TrackerConfig& config);

  // Nothing locked: the finder's best candidate in `frame` (`roi`, pixels) that is not a lock
  // dropped lately; none while it sees none.
  std::optional<BallCandidate> Choose(const Frame& frame, cv::Rect roi);
  // `c` becomes the lock, unconfirmed: reviewed at once.
  void Adopt(const BallCandidate& c);
  // The unconfirmed lock after `frame`: its sighting `obs` (shapeless: seen only as a blob
  // running on out of the frame), `ball` what the tracker knows of it.
  LockReview Review(const Frame& frame, cv::Rect roi, const BallObservation& obs, bool shapeless,
                    const FollowedBall& ball);

  bool unconfirmed() const { return unconfirmed_; }
  const BallCandidate& chosen() const { return chosen_; }
  // The frame after a choice, each true once: look first where the finder saw the ball (the
  // seed); remember the lookalikes of a colour chosen; take a brightness choice's ball out of
  // the background it starts from.
  bool TakeSeed() { return std::exchange(has_seed_, false); }
  bool TakeLookalikes() { return std::exchange(lookalikes_pending_, false); }
  bool TakeForgetBall() { return std::exchange(forget_ball_, false); }
  // Locks dropped or replaced before one was confirmed.
  int64_t dropped_locks() const { return dropped_locks_; }

 private:
  struct RejectedLock {
    double x, y, r, until_t;  // pixels, and until when (s) it stays rejected
  };
  bool Rejected(const BallCandidate& c, double t) const;
  // A candidate of the finder is the locked object: near where the lock was at the
  // candidate's time, and of its size.
  bool SameAsLock(const BallCandidate& c, double here_x, double here_y, double here_r,
                  const FollowedBall& ball) const;
  // The lock at (x, y), radius r, is not chosen again for auto_reject_s.
  void Reject(double x, double y, double r, double t);

  const TrackerConfig& config_;
  BallFinder finder_;
  BallFinder still_finder_;  // the reviews of a still lock (still_review_work_pixels)
  ArcCheck arc_;
  bool unconfirmed_ = false;
  BallCandidate chosen_;
  double last_found_t_ = 0;      // s
  double last_review_t_ = -1e9;  // s: when the finder last looked for a better candidate
  bool has_seed_ = false;
  bool lookalikes_pending_ = false;
  bool forget_ball_ = false;
  std::vector<RejectedLock> rejected_;
  int64_t dropped_locks_ = 0, choices_ = 0;
};

}  // namespace bouncefit
