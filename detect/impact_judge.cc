// Impacts in flight: whether rising samples confirm one (near the floor, where the camera
// could see it, not a straddled hop).
#include "detect/impact_judge.h"

#include <algorithm>
#include <cmath>

namespace bouncefit {

ImpactJudge::ImpactJudge(const FlightFollowerConfig& config, const DetectorScene& scene,
                         const FlightArcs& arcs, const DropHost& host)
    : config_(config), scene_(scene), arcs_(arcs), host_(host) {}

RisingVerdict ImpactJudge::Judge(const DetectorArc& cur, std::vector<DetectorSample>& rising) const {
  while (static_cast<int>(rising.size()) >= config_.impact_confirm_samples) {
    // A rebound rises: the newest sample must be above the first one off the arc; if it
    // is not, the first one was a stray detection.
    if (rising.size() == 1 || Down(rising.back()) < Down(rising.front())) {
      // High above the floor: the arc's young fit turned down too early (few samples at a
      // low frame rate); these samples belong to it.
      if (!NearTheFloor(cur, rising)) return RisingVerdict::kOnTheArc;
      if (ImpactNotSeen(rising)) {
        // No impact: the front sample starts no rebound (the arc ends by its misses).
        rising.erase(rising.begin());
        continue;
      }
      return StraddlesItsImpact(cur, rising) ? RisingVerdict::kImpactAfterHop : RisingVerdict::kImpact;
    }
    rising.erase(rising.begin());
  }
  return RisingVerdict::kWaiting;
}

bool ImpactJudge::LastSampleStraddles(const DetectorArc& fall) const {
  if (fall.samples.size() < 6) return false;
  DetectorArc probe = fall;
  const DetectorSample last = probe.samples.back();
  probe.samples.pop_back();
  if (scene_.calibrated()) arcs_.Refit(probe);
  double up, wp, vp;
  return arcs_.Predict(probe, last.t, &up, &wp, &vp) && std::abs(Down(last) - up) > scene_.FollowGate(vp);
}

bool ImpactJudge::NearTheFloor(const DetectorArc& cur, const std::vector<DetectorSample>& rising) const {
  if (!scene_.calibrated() || !scene_.calibration().calibration.has_floor || !cur.fit_ok) return true;
  const double floor = scene_.calibration().calibration.floor_centre_px();
  const double apex = floor - cur.fit.u_apex;
  if (!(apex > scene_.MinApexPx())) return true;
  // Around an impact the samples either side lie within one frame's travel of the floor,
  // so the lower of the two is in the lower part of the arc; near the apex both are high.
  const double low = floor - std::max(Down(cur.samples.back()), Down(rising.front()));
  return low < 0.6 * apex;
}

bool ImpactJudge::ImpactNotSeen(const std::vector<DetectorSample>& rising) const {
  if (rising.size() < 2) return false;
  const double gate = scene_.Gate();
  if (Down(rising.front()) - Down(rising.back()) > gate) return false;  // it rises
  // The contact, from a trial fit of the arcs with the rebound's samples as the next one.
  CalibrationInput in;
  in.utime = rising.back().utime;
  in.arcs = arcs_.Data();
  FlightArcData next;
  for (const auto& q : rising) next.samples.push_back({q.t, q.x, q.y});
  in.arcs.push_back(std::move(next));
  in.radius_px = scene_.RadiusPx();
  FlightGlobals prev_globals;
  if (scene_.calibrated()) {
    prev_globals = scene_.calibration().flight.globals;
    in.previous_globals = &prev_globals;
  }
  const CalibrationResult res = scene_.calibrator().Calibrate(in);
  const size_t j = arcs_.arcs().size() - 1;  // the impact between the current arc and the rebound
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

bool ImpactJudge::StraddlesItsImpact(const DetectorArc& cur, const std::vector<DetectorSample>& rising) const {
  const FlightImpact* began = arcs_.ImpactBeforeCurrent();
  if (!scene_.calibrated() || !scene_.calibration().calibration.has_floor || !began || cur.samples.size() > 2 ||
      rising.size() < 2)
    return false;
  const int bounce = static_cast<int>(arcs_.arcs().size() - 1) + host_.FirstBounce();
  if (host_.PeakEmitted(bounce)) return false;
  // The highest the arc can have flown: a flight from its impact to the first rising sample.
  const double g = scene_.calibration().flight.globals.gravity_px;
  const double t_max = rising.front().t - began->t;
  const double cur_max = g * t_max * t_max / 8;
  // The rebound after it, from its first two samples under the same gravity.
  const DetectorSample& p = rising[0];
  const DetectorSample& q = rising[1];
  if (!(q.t > p.t)) return false;
  const double t_apex = 0.5 * (p.t + q.t) + (Down(q) - Down(p)) / (g * (q.t - p.t));
  const double u_apex = Down(p) - 0.5 * g * (p.t - t_apex) * (p.t - t_apex);
  const double next = scene_.calibration().calibration.floor_centre_px() - u_apex;
  // A ball that is only bounced rises lower after every impact: a rebound clearly higher
  // than the arc before it could have flown means that arc was no flight.
  return next > 1.5 * cur_max + scene_.Gate();
}

}  // namespace bouncefit
