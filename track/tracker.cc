#include "track/tracker.h"

#include <fmt/format.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace bouncefit {

Tracker::Tracker(TrackerConfig config)
    : config_(std::move(config)), how_("no colour chosen yet"), camera_(config_.camera), lock_(config_), ball_(config_),
      window_(config_, roi_, lock_, ball_), whole_frame_(config_, roi_, window_, lock_, ball_), auto_(config_) {
  std::string error;
  if (!config_.IsValid(&error)) throw std::invalid_argument("tracker: " + error);
}

void Tracker::FitFrameSize(cv::Size size) {
  size_ = size;
  const cv::Rect full(0, 0, size_.width, size_.height);
  roi_ = (config_.roi_w > 0 && config_.roi_h > 0)
             ? cv::Rect(config_.roi_x, config_.roi_y, config_.roi_w, config_.roi_h) & full
             : full;
  const std::string frame_size = std::to_string(size_.width) + "x" + std::to_string(size_.height);
  if (size_.width < 8 || size_.height < 8)
    throw std::invalid_argument("tracker: a " + frame_size + " px picture is too small to find a ball in (8x8 at least)");
  if (roi_.width < 8 || roi_.height < 8)
    throw std::invalid_argument("tracker: ROI lies outside the " + frame_size + " frame");
}

BallObservation Tracker::Track(const Frame& frame) {
  BallObservation obs;
  obs.utime = frame.utime;
  obs.frame = frame.index;
  if (frame.image.empty()) throw std::invalid_argument("tracker: empty frame");
  CheckFrameFormat(frame);
  if (frame.image.size() != size_) FitFrameSize(frame.image.size());
  ++frames_;
  const double t = static_cast<double>(frame.utime) * 1e-6;
  // A brightness lock reads the frame's luma first: the camera's profiles reuse it when the
  // source gave none of its own (a BGR frame's; a YUYV frame's is rescaled there and taken
  // raw here).
  const bool had_luma = lock_.brightness();
  if (had_luma) SetLumaFrame(frame);
  if (config_.follow_camera) {
    // The decoder's own luma where the source kept it (the Y the BGR picture was made from:
    // no conversion back), else a brightness lock's.
    const bool own = !frame.luma.empty();
    const bool shared = lock_.brightness() && frame.format != PixelFormat::kYuyv;
    camera_.Update(frame, ball_.WhereBallMayBe(t), own ? &frame.luma : shared ? &lock_.luma() : nullptr,
                   own && frame.luma_limited_range ? 255.0 / 219.0 : 1.0, own ? frame.luma_turn_cw_deg : 0);
    obs.camera_dx = static_cast<float>(camera_.dx());
    obs.camera_dy = static_cast<float>(camera_.dy());
  }
  // The prediction and the arc check follow the ball in the scene: a held camera's jitter
  // is not the ball's motion.
  ball_.SetCameraShift(obs.camera_dx, obs.camera_dy);
  if (!lock_.valid() && !ChooseColor(frame)) {
    ball_.Missed();
    return obs;
  }
  // Brightness chosen just now (given, or the automatic choice's): a lock that held at the
  // top has its colour, so ChooseColor did not run and could not replace it.
  if (lock_.brightness() && !had_luma) SetLumaFrame(frame);
  // Chosen just now: the ball is in the first background; take it out.
  if (lock_.brightness() && auto_.TakeForgetBall()) lock_.ForgetBall(auto_.chosen().x, auto_.chosen().y, auto_.chosen().r);
  if (auto_.TakeLookalikes()) whole_frame_.RememberLookalikes(frame, auto_.chosen());
  Prediction prediction;
  bool ok = ball_.Predict(t, &prediction) && window_.FindNearPrediction(frame, prediction, &obs);
  if (!ok && auto_.TakeSeed()) {
    // Just chosen automatically: look where the finder saw it before searching everywhere.
    const BallCandidate& c = auto_.chosen();
    const cv::Point2f seed(static_cast<float>(c.x), static_cast<float>(c.y));
    ok = window_.Find(frame, seed, 3 * c.r + 12, 2 * c.r + 10, &obs);
  }
  if (!ok) ok = whole_frame_.Acquire(frame, &obs);
  if (ok) {
    ball_.Found(t, obs);
    ++found_;
  } else {
    ball_.Missed();
  }
  if (lock_.brightness()) lock_.UpdateBackground(ok, obs, ball_.radius(), ball_.last_x(), ball_.last_y());
  tentative_ = ok && auto_.unconfirmed() && window_.shapeless();
  if (auto_.unconfirmed()) ReviewAutoLock(frame, obs);
  return obs;
}

bool Tracker::ChooseColor(const Frame& frame) {
  if (lock_.StartNamed(frame, &how_)) return true;
  if (const std::optional<BallCandidate> c = auto_.Choose(frame, roi_)) {
    Adopt(*c);
    return true;
  }
  if (!how_.starts_with("automatic: dropped"))
    how_ = "automatic: waiting for a round blob that moves and stands out of its surroundings";
  return false;
}

void Tracker::Adopt(const BallCandidate& c) {
  auto_.Adopt(c);
  ball_.Restart(c.r);
  whole_frame_.Restart();
  if (c.by_luma) {
    how_ = "automatic: " + c.Why() + lock_.StartBrightness(c.polarity, c.contrast);
  } else {
    lock_.StartColor(c.color);
    how_ = "automatic: " + c.Why() + ": " + lock_.color().ToString();
  }
}

void Tracker::ReviewAutoLock(const Frame& frame, const BallObservation& obs) {
  const LockReview review = auto_.Review(frame, roi_, obs, window_.shapeless(), ball_);
  switch (review.verdict) {
    case LockReview::Verdict::kKeep:
      break;
    case LockReview::Verdict::kConfirmed:
      how_ += review.what;
      break;
    case LockReview::Verdict::kSwitch:
      Adopt(review.next);
      break;
    case LockReview::Verdict::kDrop:
      lock_.Drop();
      ball_.Forget();
      how_ = review.what;
      break;
  }
}

void Tracker::SetLumaFrame(const Frame& frame) {
  const double followed_r = ball_.FollowedRadius();
  lock_.SetFrame(frame, ball_.IsCloseUp(followed_r) ? followed_r : 0);
}

bool Tracker::FindInEarlierFrame(const Frame& frame, cv::Point2f centre, double reach_px, double sweep_px,
                                 BallObservation* obs, bool replaces, double cut_radius_px) {
  if (!lock_.valid() || lock_.brightness() || ball_.radius() <= 0 || frame.image.size() != size_) return false;
  // What the search of the frame being tracked set for itself: no prediction here, no box
  // limit from its speed.
  const FrameExpectation now = ball_.expected();
  ball_.set_expected({});
  const bool ok = window_.FindInEarlierFrame(frame, centre, reach_px, sweep_px, obs, cut_radius_px);
  ball_.set_expected(now);
  if (ok && replaces) --found_;
  if (ok) ++found_earlier_;
  return ok;
}

std::string Tracker::Describe() const {
  std::string text = fmt::format("tracker: {}; found in {} of {} frames, {} full-frame searches", how_,
                                 found_ + found_earlier_, frames_, acquisitions());
  if (found_earlier_ > 0) text += fmt::format("; {} of those found looking back from a later sighting", found_earlier_);
  if (auto_.dropped_locks() > 0)
    text += fmt::format("; automatic locks dropped or replaced before one was ballistic: {}", auto_.dropped_locks());
  if (camera_.moving()) {
    text += fmt::format("; the camera moved (held in a hand?): up to {:.1f} px from where it started, taken out of the "
                        "ball's track",
                        camera_.max_offset());
    if (camera_.unmeasured() > 0) text += fmt::format(" ({} frames not measurable)", camera_.unmeasured());
  }
  return text;
}

}  // namespace bouncefit
