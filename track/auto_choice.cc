#include "track/auto_choice.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace bouncefit {

namespace {
BallFinderParams StillReviewParams(const TrackerConfig& c) {
  BallFinderParams p = c.finder;
  if (c.still_review_work_pixels > 0) p.max_work_pixels = std::min(p.max_work_pixels, c.still_review_work_pixels);
  return p;
}
}  // namespace

AutoChoice::AutoChoice(const TrackerConfig& config)
    : config_(config), finder_(config.finder, config.color), still_finder_(StillReviewParams(config), config.color),
      arc_(config.arc) {}

std::optional<BallCandidate> AutoChoice::Choose(const Frame& frame, cv::Rect roi) {
  const double t = static_cast<double>(frame.utime) * 1e-6;
  const auto cands = finder_.Find(frame, roi);
  still_finder_.Remember(frame, roi);
  for (const BallCandidate& c : cands)
    if (!Rejected(c, t)) return c;
  return std::nullopt;
}

bool AutoChoice::Rejected(const BallCandidate& c, double t) const {
  for (const RejectedLock& r : rejected_)
    if (t < r.until_t && std::hypot(c.x - r.x, c.y - r.y) < 1.5 * std::max(r.r, c.r) + 4) return true;
  return false;
}

void AutoChoice::Reject(double x, double y, double r, double t) {
  rejected_.push_back({x, y, r, t + config_.auto_reject_s});
}

void AutoChoice::Adopt(const BallCandidate& c) {
  chosen_ = c;
  unconfirmed_ = true;
  last_review_t_ = -1e9;  // a new choice is reviewed at once (pingpong_white: a wrong one)
  last_found_t_ = c.t;
  has_seed_ = true;
  arc_.Reset();
  ++choices_;
  if (c.by_luma)
    forget_ball_ = true;
  else
    lookalikes_pending_ = true;
}

LockReview AutoChoice::Review(const Frame& frame, cv::Rect roi, const BallObservation& obs, bool shapeless_lock,
                              const FollowedBall& ball) {
  LockReview review;
  const double t = static_cast<double>(frame.utime) * 1e-6;
  if (obs.found) last_found_t_ = t;
  const bool shapeless = obs.found && shapeless_lock;
  // A ball too little in view to place is where its box is, a sample no arc is made of.
  if (obs.found && arc_.Add(t, SeenX(obs) - ball.shift_x(), SeenY(obs) - ball.shift_y(), obs.radius_px,
                            !shapeless && CentrePlaced(obs))) {
    unconfirmed_ = false;
    review.verdict = LockReview::Verdict::kConfirmed;
    review.what = fmt::format("; confirmed at {:.2f} s: its track became a ballistic arc", t);
    if (choices_ > 1) review.what += fmt::format(" (choice {})", choices_);
    return review;
  }
  const double here_x = obs.found ? SeenX(obs) : ball.last_x(), here_y = obs.found ? SeenY(obs) : ball.last_y();
  const double here_r = std::max(ball.radius(), chosen_.r);
  std::string drop;
  if (arc_.moving_s() > config_.auto_drop_moving_s)
    drop = fmt::format("moved for {:.1f} s without a ballistic arc", arc_.moving_s());
  else if (t - last_found_t_ > config_.auto_drop_lost_s)
    drop = fmt::format("not seen for {:.1f} s", t - last_found_t_);
  const bool still = obs.found && arc_.RecentTravel(0.2) < 0.5 * here_r;
  // A lock seen only as a blob running on out of the frame (an arm reaching in from its edge)
  // shows no shape to be a ball by: it is reviewed as a still one is, and a ball elsewhere
  // replaces it.
  const bool unsure = still || shapeless;
  // A lock that holds, moves and has its colour looks at no candidate below: the finder only
  // keeps its history then (the search is most of the tracking time until a lock confirms).
  // One that follows brightness looks every frame (the same ball may show a colour of its
  // own, and the sooner the better), unless it had a colour that its brightness outweighed
  // (the finder sees it so again: its colour is never adopted); one that stands still (a ball
  // held before the drop, or a decoy while the ball is held), every auto_review_s.
  const bool looks_for_colour = obs.found && chosen_.by_luma && chosen_.weaker_colour <= 0;
  const bool due = t - last_review_t_ >= config_.auto_review_s;
  if (drop.empty() && !looks_for_colour && (!unsure || !due)) {
    finder_.Remember(frame, roi);
    still_finder_.Remember(frame, roi);
    return review;
  }
  last_review_t_ = t;
  // With the lock holding, a review only asks whether something else moves like a ball (a
  // still lock) or the same ball shows a colour of its own (a brightness lock). Smaller
  // frames look first: only a candidate there that could matter (elsewhere, a quarter of the
  // strength a switch needs; by colour, near a brightness lock) sends the finder to its own
  // size, which decides as always. A shapeless lock's review looks at the finder's size at
  // once: the ball it hides may have left it small and fast (a toss from the hand).
  if (drop.empty() && !shapeless) {
    bool worth_a_look = false;
    for (const BallCandidate& c : still_finder_.Find(frame, roi)) {
      const double d = std::hypot(c.x - here_x, c.y - here_y), near = 3 * std::max(here_r, c.r);
      worth_a_look = worth_a_look || (looks_for_colour && !c.by_luma && d < 1.5 * near) ||
                     (unsure && !Rejected(c, t) && d >= near && c.score >= 0.25 * 0.5 * chosen_.score);
    }
    if (!worth_a_look) {
      finder_.Remember(frame, roi);
      return review;
    }
  } else {
    still_finder_.Remember(frame, roi);
  }
  const std::vector<BallCandidate> found = finder_.Find(frame, roi);
  for (const BallCandidate& c : found) {
    const bool same = std::hypot(c.x - here_x, c.y - here_y) < 3 * std::max(here_r, c.r);
    if (obs.found && chosen_.by_luma && !c.by_luma && SameAsLock(c, here_x, here_y, here_r, ball)) {
      // The same ball, now with a colour of its own against its surroundings: colour
      // segments it better than a background model.
      review.verdict = LockReview::Verdict::kSwitch;
      review.next = c;
      return review;
    }
    if (Rejected(c, t) || same) continue;
    if (drop.empty() && !(unsure && c.score >= 0.5 * chosen_.score)) break;
    // The lock failed, or stands still while something else moves like a ball: switch.
    if (!drop.empty()) Reject(here_x, here_y, here_r, t);
    ++dropped_locks_;
    review.verdict = LockReview::Verdict::kSwitch;
    review.next = c;
    return review;
  }
  if (drop.empty()) return review;
  Reject(here_x, here_y, here_r, t);
  ++dropped_locks_;
  unconfirmed_ = false;
  review.verdict = LockReview::Verdict::kDrop;
  review.what =
      fmt::format("automatic: dropped the lock at {:.0f},{:.0f} ({}); waiting for another", here_x, here_y, drop);
  return review;
}

bool AutoChoice::SameAsLock(const BallCandidate& c, double here_x, double here_y, double here_r,
                            const FollowedBall& ball) const {
  // Where the lock was when the finder saw the candidate (its middle frame, a lag before
  // now, or the newest): a ball falling at 20 fps moves radii a frame, and a patch of colour
  // three radii from where the lock is now may be six from where it was then.
  double x = here_x, y = here_y;
  if (arc_.PositionAt(c.t, &x, &y)) x += ball.shift_x(), y += ball.shift_y();
  return std::hypot(c.x - x, c.y - y) < 3 * std::max(here_r, c.r) && ball.SizeMatches(c.r, here_r);
}

}  // namespace bouncefit
