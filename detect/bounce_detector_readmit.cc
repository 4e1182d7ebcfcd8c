// Arcs take back the samples of their flight that the scale of the moment turned away.
#include "detect/bounce_detector.h"

#include <algorithm>
#include <cmath>

namespace bouncefit {

bool BounceDetector::ReadmitSamples() {
  if (!calibrated_ || arcs_.size() < 2) return false;
  const auto& imps = calibration_.impacts;
  bool gained = false;
  // The current arc is still followed sample by sample: only arcs closed by an impact.
  for (size_t j = 0; j + 1 < arcs_.size(); ++j) {
    Arc& arc = arcs_[j];
    if (!arc.fit_ok || arc.samples.empty() || j >= imps.size() || !imps[j].ok) continue;
    if (j > 0 && (j - 1 >= imps.size() || !imps[j - 1].ok)) continue;
    const double t_from = j == 0 ? arc.samples.front().t : imps[j - 1].t;
    const double t_to = imps[j].t;
    std::vector<Sample> taken;
    for (const Sample& q : flight_seen_) {
      // A picture within a frame of an impact may straddle it (the exposure sees the ball
      // fall and rise): it lies on neither arc, and the follower judged it as such.
      const bool at_impact = (j > 0 && q.t < t_from + frame_dt_) || q.t > t_to - frame_dt_;
      if (q.t <= t_from || q.t >= t_to || at_impact) continue;
      const bool kept = std::any_of(arc.samples.begin(), arc.samples.end(),
                                    [&](const Sample& a) { return a.t == q.t; });
      if (kept) continue;
      double u, w, v;
      if (!Predict(arc, q.t, &u, &w, &v)) continue;
      // The gate a sample of a known arc is followed with (OnFlight).
      const double gate = FollowGate(v);
      if (std::abs(Down(q) - u) <= gate && std::abs(Floor(q) - w) <= 2 * gate) taken.push_back(q);
    }
    if (taken.empty()) continue;
    arc.samples.insert(arc.samples.end(), taken.begin(), taken.end());
    std::sort(arc.samples.begin(), arc.samples.end(),
              [](const Sample& a, const Sample& b) { return a.t < b.t; });
    gained = true;
  }
  return gained;
}

}  // namespace bouncefit
