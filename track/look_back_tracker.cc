#include "track/look_back_tracker.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {
namespace {

// Where the ball was in the scene (the camera's own motion taken out), pixels.
cv::Point2d InScene(const BallObservation& o) { return {o.cx - o.camera_dx, o.cy - o.camera_dy}; }

double Seconds(int64_t utime) { return static_cast<double>(utime) * 1e-6; }

}  // namespace

LookBackTracker::LookBackTracker(Tracker& tracker, LookBackConfig config) : tracker_(tracker), config_(config) {
  if (!(config_.max_wait_s >= 0) || config_.max_frames < 0 || !(config_.tentative_wait_s >= 0) ||
      config_.tentative_frames < 0)
    throw std::invalid_argument("look back: the wait must be >= 0 s and >= 0 frames");
}

std::vector<TrackedFrame> LookBackTracker::Track(const Frame& frame) {
  TrackedFrame tracked{frame, tracker_.Track(frame), tracker_.tentative()};
  // A waiting picture must outlive the source's next one.
  if (!frame.owns_image) tracked.frame.image = frame.image.clone();
  if (!frame.luma.empty() && !frame.luma_owner) tracked.frame.luma = frame.luma.clone();
  waiting_.push_back(std::move(tracked));

  std::vector<TrackedFrame> out;
  const size_t first = FirstFound();
  // Found after frames without it: look back from here when its motion is known, from the
  // sighting before those frames or from the frame after this one.
  if (first == 0 || (first < waiting_.size() && (before_ || first + 1 < waiting_.size()))) {
    LookBack(first);
    Settle(waiting_.size(), &out);
  }
  while (!waiting_.empty()) {
    const bool tentative = waiting_.front().tentative;
    const size_t frames = static_cast<size_t>(tentative ? config_.tentative_frames : config_.max_frames);
    const double wait = tentative ? config_.tentative_wait_s : config_.max_wait_s;
    if (waiting_.size() <= frames && Seconds(waiting_.back().frame.utime - waiting_.front().frame.utime) <= wait) break;
    Settle(1, &out);
  }
  return out;
}

std::vector<TrackedFrame> LookBackTracker::Flush() {
  LookBack(FirstFound());
  std::vector<TrackedFrame> out;
  Settle(waiting_.size(), &out);
  return out;
}

size_t LookBackTracker::FirstFound() const {
  size_t first = 0;
  while (first < waiting_.size() && (!CentrePlaced(waiting_[first].obs) || waiting_[first].tentative)) ++first;
  return first;
}

void LookBackTracker::LookBack(size_t first) {
  if (first == 0 || first >= waiting_.size()) return;
  const BallObservation* a = &waiting_[first].obs;  // the sighting just after the frame looked at
  const BallObservation* b =
      first + 1 < waiting_.size() && CentrePlaced(waiting_[first + 1].obs) ? &waiting_[first + 1].obs : nullptr;
  for (size_t k = first; k-- > 0;) {
    TrackedFrame& w = waiting_[k];
    const double tk = Seconds(w.frame.utime), ta = Seconds(a->utime);
    const cv::Point2d pa = InScene(*a);
    cv::Point2d centre = pa;
    double reach = a->radius_px, speed = 0;  // px beyond the ball's radius; px/s
    if (before_) {
      // Between two sightings: on the line joining them, anywhere an impact between may have
      // bent the path to.
      const cv::Point2d pb = InScene(*before_);
      const double tb = Seconds(before_->utime);
      centre = pb + (pa - pb) * ((tk - tb) / (ta - tb));
      reach = cv::norm(pa - pb);
      speed = reach / (ta - tb);
    } else if (b) {
      // Before the first sightings: back along their motion, slower the further back (a
      // fall from rest): between where it was next and where that speed would have put it.
      const cv::Point2d v = (InScene(*b) - pa) / (Seconds(b->utime) - ta);
      speed = cv::norm(v);
      centre = pa - 0.5 * v * (ta - tk);
      reach = 0.5 * speed * (ta - tk);
    }
    const cv::Point2f in_frame(static_cast<float>(centre.x + w.obs.camera_dx),
                               static_cast<float>(centre.y + w.obs.camera_dy));
    BallObservation found = w.obs;
    // A frame already counted (a tentative lock's, or the ball too little in view to place).
    const bool counted = w.tentative || w.obs.found;
    // A ball the border cuts there is placed with the radius of the sighting after it (a ball
    // moving towards the camera or away changes size).
    if (!tracker_.FindInEarlierFrame(w.frame, in_frame, reach, speed * (ta - tk), &found, counted, a->radius_px))
      return;
    const bool placed = CentrePlaced(found);
    // Across the picture a ball between two sightings keeps between them (its sideways speed
    // is steady in flight; an impact may slow it, not send it back): a thing of its colour
    // beside its path, where it vanished before a patch of its hue, is not it.
    if (before_ && placed) {
      const double x = InScene(found).x, margin = 0.5 * found.radius_px + 2;
      if (x < std::min(pa.x, InScene(*before_).x) - margin || x > std::max(pa.x, InScene(*before_).x) + margin)
        return;
    }
    w.obs = found;
    w.tentative = false;
    // Too little of it in view to place: the look goes on from the last centre placed.
    if (placed) b = a, a = &w.obs;
  }
}

void LookBackTracker::Settle(size_t n, std::vector<TrackedFrame>* out) {
  for (size_t i = 0; i < n && !waiting_.empty(); ++i) {
    TrackedFrame& f = waiting_.front();
    before_ = CentrePlaced(f.obs) && !f.tentative ? std::optional<BallObservation>(f.obs) : std::nullopt;
    out->push_back(std::move(f));
    waiting_.pop_front();
  }
}

}  // namespace bouncefit
