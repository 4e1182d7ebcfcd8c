// The drop's samples in flight and the closed arcs taking them back.
#include "detect/flight_samples.h"

#include <algorithm>
#include <cmath>

namespace bouncefit {

FlightSamples::FlightSamples(const DetectorScene& scene) : scene_(scene) {}

void FlightSamples::Saw(const DetectorSample& s) {
  if (seen_.size() < kKept) seen_.push_back(s);
}

void FlightSamples::Clear() { seen_.clear(); }

void FlightSamples::RescaleTime(double k) {
  for (auto& q : seen_) q.t *= k;
}

bool FlightSamples::ReadmitInto(FlightArcs& flight) const {
  std::vector<DetectorArc>& arcs = flight.arcs();
  if (!scene_.calibrated() || arcs.size() < 2) return false;
  const auto& imps = scene_.calibration().impacts;
  bool gained = false;
  // The current arc is still followed sample by sample: only arcs closed by an impact.
  for (size_t j = 0; j + 1 < arcs.size(); ++j) {
    DetectorArc& arc = arcs[j];
    if (!arc.fit_ok || arc.samples.empty() || j >= imps.size() || !imps[j].ok) continue;
    if (j > 0 && (j - 1 >= imps.size() || !imps[j - 1].ok)) continue;
    const double t_from = j == 0 ? arc.samples.front().t : imps[j - 1].t;
    const double t_to = imps[j].t;
    std::vector<DetectorSample> taken;
    for (const DetectorSample& q : seen_) {
      // A picture within a frame of an impact may straddle it (the exposure sees the ball
      // fall and rise): it lies on neither arc, and the follower judged it as such.
      const bool at_impact = (j > 0 && q.t < t_from + scene_.frame_dt()) || q.t > t_to - scene_.frame_dt();
      if (q.t <= t_from || q.t >= t_to || at_impact) continue;
      const bool kept = std::any_of(arc.samples.begin(), arc.samples.end(),
                                    [&](const DetectorSample& a) { return a.t == q.t; });
      if (kept) continue;
      double u, w, v;
      if (!flight.Predict(arc, q.t, &u, &w, &v)) continue;
      // The gate a sample of a known arc is followed with (FlightFollower::OnFlight).
      const double gate = scene_.FollowGate(v);
      if (std::abs(scene_.Down(q) - u) <= gate && std::abs(scene_.Floor(q) - w) <= 2 * gate) taken.push_back(q);
    }
    if (taken.empty()) continue;
    arc.samples.insert(arc.samples.end(), taken.begin(), taken.end());
    std::sort(arc.samples.begin(), arc.samples.end(),
              [](const DetectorSample& a, const DetectorSample& b) { return a.t < b.t; });
    gained = true;
  }
  return gained;
}

}  // namespace bouncefit
