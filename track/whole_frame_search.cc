#include "track/whole_frame_search.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace bouncefit {

void WholeFrameSearch::Restart() {
  lookalikes_.clear();
  last_candidates_.clear();
}

void WholeFrameSearch::RememberLookalikes(const Frame& frame, const BallCandidate& chosen) {
  lock_.Planes(frame, roi_, 2, 0.5 * config_.blur_sigma_px, &wide_);
  cv::Mat mask;
  for (const Blob& b : SegmentBlobs(wide_, lock_.color(), ball_.SegmentParamsFor(chosen.r, roi_), &mask)) {
    const double r = EquivalentRadius(b);
    if (std::hypot(b.centroid.x - chosen.x, b.centroid.y - chosen.y) < 2 * (r + chosen.r)) continue;
    if (lookalikes_.size() < 32) lookalikes_.push_back({b.centroid, static_cast<float>(r), true});
  }
}

bool WholeFrameSearch::Acquire(const Frame& frame, BallObservation* obs) {
  ++acquisitions_;
  lock_.Planes(frame, roi_, 2, 0.5 * config_.blur_sigma_px, &wide_);
  cv::Mat wide_mask;
  std::vector<Blob> blobs =
      SegmentBlobs(wide_, lock_.color(), ball_.SegmentParamsFor(ball_.FollowedRadius(), roi_), &wide_mask);
  const double tol = lock_.color().tolerance();
  const double radius = ball_.radius();
  double px = 0, py = 0;
  const bool have_pred = ball_.lost() <= config_.lost_frames_keep &&
                         ball_.PredictInFrame(static_cast<double>(frame.utime) * 1e-6, &px, &py);
  std::vector<std::pair<double, size_t>> order;
  for (size_t k = 0; k < blobs.size(); ++k) {
    const Blob& b = blobs[k];
    const double r = EquivalentRadius(b);
    // Brightness mode acquires only what moves: not the ghost a ball held still leaves in
    // the background model, nor a patch of wall the light changed.
    if (lock_.brightness() && lock_.MovedFraction(b.box) < 0.15) continue;
    // Colour first (a similar-hue object is a worse match), then shape, size, prediction.
    double score = 3 * b.mean_distance / tol + std::abs(b.fill - 0.785);
    if (radius > 0) score += std::abs(r - radius) / radius;
    if (have_pred) score += std::hypot(b.centroid.x - px, b.centroid.y - py) / (radius + 20);
    bool lookalike = false;
    for (const Lookalike& m : lookalikes_)
      if (std::hypot(b.centroid.x - m.p.x, b.centroid.y - m.p.y) < std::max(3.0, 0.3 * m.r)) {
        score += 3;
        // Of the ball's hue, where it already was when the ball was chosen, and unmoved:
        // never the ball (which moved to be chosen), unless the prediction brings it there.
        lookalike = lookalike || (m.at_choice && std::abs(EquivalentRadius(b) - m.r) < 0.3 * m.r + 1.5);
      }
    if (lookalike && (!have_pred || std::hypot(b.centroid.x - px, b.centroid.y - py) > 2 * radius + 4)) continue;
    bool moved = !last_candidates_.empty();
    for (const Blob& o : last_candidates_)
      if (std::hypot(b.centroid.x - o.centroid.x, b.centroid.y - o.centroid.y) < 1.5) moved = false;
    if (moved) score -= 0.5;
    order.emplace_back(score, k);
  }
  std::sort(order.begin(), order.end());
  last_candidates_ = blobs;
  // Try the best few: the half-resolution blob must hold up at full resolution.
  for (size_t i = 0; i < order.size() && i < 3; ++i) {
    const Blob& b = blobs[order[i].second];
    const double r = EquivalentRadius(b);
    // A ball the frame's border cuts shows a cap whose chord along the border is as long as
    // its radius once the cap is an eighth of a radius deep; a shorter sliver there (a glint at
    // the top of the frame while the ball falls at its bottom) is not taken for the ball.
    if (radius > 0 && window_.CutByRoiBorder(b.box) && std::max(b.box.width, b.box.height) < radius) continue;
    if (window_.Find(frame, b.centroid, 1.6 * r + 10, r + 4, obs)) {
      // What it passed over that is not the ball: a lookalike, unless known already.
      for (const auto& [s, k] : order) {
        const Blob& o = blobs[k];
        if (std::hypot(o.centroid.x - SeenX(*obs), o.centroid.y - SeenY(*obs)) < 2 * obs->radius_px) continue;
        bool known = false;
        for (const Lookalike& m : lookalikes_)
          if (std::hypot(o.centroid.x - m.p.x, o.centroid.y - m.p.y) < 3) known = true;
        if (!known && lookalikes_.size() < 16)
          lookalikes_.push_back({o.centroid, static_cast<float>(EquivalentRadius(o))});
      }
      return true;
    }
  }
  return false;
}

}  // namespace bouncefit
