// The samples the current arc turned away and the misses they count.
#include "detect/off_arc_samples.h"

#include <algorithm>
#include <cmath>

namespace bouncefit {

void OffArcSamples::TurnAway(const DetectorSample& s, bool rising) {
  ++misses_;
  (rising ? rising_ : other_).push_back(s);
}

void OffArcSamples::Clear() {
  rising_.clear();
  other_.clear();
  misses_ = 0;
}

void OffArcSamples::Reset() {
  Clear();
  last_far_.reset();
}

void OffArcSamples::RescaleTime(double k) {
  for (auto* pending : {&rising_, &other_})
    for (auto& q : *pending) q.t *= k;
}

std::vector<DetectorSample> OffArcSamples::InTimeOrder() const {
  std::vector<DetectorSample> all = other_;
  all.insert(all.end(), rising_.begin(), rising_.end());
  std::sort(all.begin(), all.end(), [](const DetectorSample& x, const DetectorSample& y) { return x.t < y.t; });
  return all;
}

double OffArcSamples::LastT(double t_arc) const {
  double last = t_arc;
  for (const auto* pending : {&other_, &rising_})
    if (!pending->empty()) last = std::max(last, pending->back().t);
  return last;
}

bool OffArcSamples::FarAgain(const DetectorSample& s, bool far, double gate) {
  const bool again = far && last_far_ && std::hypot(s.x - last_far_->x, s.y - last_far_->y) <= s.r + gate;
  last_far_.reset();
  if (far) last_far_ = s;
  return again;
}

}  // namespace bouncefit
