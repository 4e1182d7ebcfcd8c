// Impacts in flight: whether rising samples confirm one (near the floor, where the camera
// could see it, not a straddled hop), the next arc it begins, and the samples the closed
// arcs take back under a new scale.
#include "detect/flight_follower.h"

#include <algorithm>
#include <cmath>

namespace bouncefit {

bool FlightFollower::NearTheFloor(const DetectorArc& cur) const {
  if (!scene_.calibrated() || !scene_.calibration().calibration.has_floor || !cur.fit_ok) return true;
  const double floor = scene_.calibration().calibration.floor_centre_px();
  const double apex = floor - cur.fit.u_apex;
  if (!(apex > scene_.MinApexPx())) return true;
  // Around an impact the samples either side lie within one frame's travel of the floor,
  // so the lower of the two is in the lower part of the arc; near the apex both are high.
  const double low = floor - std::max(Down(cur.samples.back()), Down(pending_up_.front()));
  return low < 0.6 * apex;
}

bool FlightFollower::ImpactNotSeen() const {
  if (pending_up_.size() < 2) return false;
  const double gate = scene_.Gate();
  if (Down(pending_up_.front()) - Down(pending_up_.back()) > gate) return false;  // it rises
  // The contact, from a trial fit of the arcs with the rebound's samples as the next one.
  CalibrationInput in;
  in.utime = pending_up_.back().utime;
  in.arcs = ArcData();
  FlightArcData next;
  for (const auto& q : pending_up_) next.samples.push_back({q.t, q.x, q.y});
  in.arcs.push_back(std::move(next));
  in.radius_px = scene_.RadiusPx();
  FlightGlobals prev_globals;
  if (scene_.calibrated()) {
    prev_globals = scene_.calibration().flight.globals;
    in.previous_globals = &prev_globals;
  }
  const CalibrationResult res = scene_.calibrator().Calibrate(in);
  const size_t j = arcs_.size() - 1;  // the impact between the current arc and the rebound
  if (!res.flight.ok || j >= res.impacts.size() || !res.impacts[j].ok) return false;
  const FlightImpact& imp = res.impacts[j];
  const double roll = res.flight.globals.roll_rad;
  bool near = false;
  for (const auto& q : scene_.seen()) {
    const double dt = q.t - imp.t;
    if (std::abs(dt) > scene_.frame_dt()) continue;
    near = true;
    // From a sample this close the ball reaches the contact within its speed there (its
    // fastest on that branch) times the time between them, or half a frame: an exposure that
    // straddles the contact shows the ball at most half a frame's travel above it.
    const double speed = dt < 0 ? imp.speed_in : imp.speed_out;
    const double reach = speed * std::max(std::abs(dt), 0.5 * scene_.frame_dt()) + gate;
    if (imp.u - AlongDown(q.x, q.y, roll) <= reach) return false;
  }
  return near;  // seen near it, never near enough; unseen around it: the ball was lost there
}

const FlightImpact* FlightFollower::ImpactBeforeCurrentArc() const {
  if (arcs_.size() < 2) return nullptr;
  const size_t j = arcs_.size() - 2;  // impacts[j] lies between arcs j and j + 1
  if (j >= scene_.calibration().impacts.size() || !scene_.calibration().impacts[j].ok) return nullptr;
  return &scene_.calibration().impacts[j];
}

bool FlightFollower::StraddlesItsImpact(const DetectorArc& cur) const {
  const FlightImpact* began = ImpactBeforeCurrentArc();
  if (!scene_.calibrated() || !scene_.calibration().calibration.has_floor || !began || cur.samples.size() > 2 ||
      pending_up_.size() < 2)
    return false;
  const int bounce = static_cast<int>(arcs_.size() - 1) + host_.FirstBounce();
  if (host_.PeakEmitted(bounce)) return false;
  // The highest the arc can have flown: a flight from its impact to the first rising sample.
  const double g = scene_.calibration().flight.globals.gravity_px;
  const double t_max = pending_up_.front().t - began->t;
  const double cur_max = g * t_max * t_max / 8;
  // The rebound after it, from its first two samples under the same gravity.
  const DetectorSample& p = pending_up_[0];
  const DetectorSample& q = pending_up_[1];
  if (!(q.t > p.t)) return false;
  const double t_apex = 0.5 * (p.t + q.t) + (Down(q) - Down(p)) / (g * (q.t - p.t));
  const double u_apex = Down(p) - 0.5 * g * (p.t - t_apex) * (p.t - t_apex);
  const double next = scene_.calibration().calibration.floor_centre_px() - u_apex;
  // A ball that is only bounced rises lower after every impact: a rebound clearly higher
  // than the arc before it could have flown means that arc was no flight.
  return next > 1.5 * cur_max + scene_.Gate();
}

void FlightFollower::ForgetStraddlingArc() {
  const size_t idx = arcs_.size() - 1;
  host_.ForgetImpact(static_cast<int>(idx) + host_.FirstBounce());
  arcs_.pop_back();
}

void FlightFollower::ConfirmImpact(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  // The last sample of the falling arc may straddle the impact too: drop it if the samples
  // before it put it off the arc (it would bend the fall, and the scale with it).
  {
    DetectorArc& prev = arcs_.back();
    if (prev.samples.size() >= 6) {
      DetectorArc probe = prev;
      const DetectorSample last = probe.samples.back();
      probe.samples.pop_back();
      if (scene_.calibrated()) RefitArc(probe);
      double up, wp, vp;
      if (Predict(probe, last.t, &up, &wp, &vp) &&
          std::abs(Down(last) - up) > scene_.FollowGate(vp))
        prev.samples.pop_back();
    }
  }
  DetectorArc next;
  next.samples = pending_up_;
  pending_up_.clear();
  pending_off_.clear();
  misses_ = 0;
  arcs_.push_back(next);
  host_.OnImpactConfirmed(s, ev);
}

bool FlightFollower::ReadmitSamples() {
  if (!scene_.calibrated() || arcs_.size() < 2) return false;
  const auto& imps = scene_.calibration().impacts;
  bool gained = false;
  // The current arc is still followed sample by sample: only arcs closed by an impact.
  for (size_t j = 0; j + 1 < arcs_.size(); ++j) {
    DetectorArc& arc = arcs_[j];
    if (!arc.fit_ok || arc.samples.empty() || j >= imps.size() || !imps[j].ok) continue;
    if (j > 0 && (j - 1 >= imps.size() || !imps[j - 1].ok)) continue;
    const double t_from = j == 0 ? arc.samples.front().t : imps[j - 1].t;
    const double t_to = imps[j].t;
    std::vector<DetectorSample> taken;
    for (const DetectorSample& q : flight_seen_) {
      // A picture within a frame of an impact may straddle it (the exposure sees the ball
      // fall and rise): it lies on neither arc, and the follower judged it as such.
      const bool at_impact = (j > 0 && q.t < t_from + scene_.frame_dt()) || q.t > t_to - scene_.frame_dt();
      if (q.t <= t_from || q.t >= t_to || at_impact) continue;
      const bool kept = std::any_of(arc.samples.begin(), arc.samples.end(),
                                    [&](const DetectorSample& a) { return a.t == q.t; });
      if (kept) continue;
      double u, w, v;
      if (!Predict(arc, q.t, &u, &w, &v)) continue;
      // The gate a sample of a known arc is followed with (OnFlight).
      const double gate = scene_.FollowGate(v);
      if (std::abs(Down(q) - u) <= gate && std::abs(Floor(q) - w) <= 2 * gate) taken.push_back(q);
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
