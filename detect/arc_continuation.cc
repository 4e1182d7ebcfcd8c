// Samples an arc turned away that are still its flight: a young rebound's, a young fall's,
// a long arc's under a gravity that is off.
#include "detect/arc_continuation.h"
#include "detect/detector_stats.h"

#include <algorithm>
#include <cmath>

namespace bouncefit {

using detector_stats::ParabolaAt;

ArcContinuation::ArcContinuation(const DetectorScene& scene, const FlightArcs& arcs)
    : scene_(scene), arcs_(arcs) {}

bool ArcContinuation::YoungReboundContinues(const DetectorArc& cur,
                                            const std::vector<DetectorSample>& missed,
                                            DetectorArc* rebound) const {
  if (!scene_.calibrated() || cur.release || cur.samples.size() > 3 || missed.size() < 2) return false;
  const FlightGlobals& g = scene_.calibration().flight.globals;
  auto offset = [&](const DetectorArc& a, const DetectorSample& q) {
    double x, y;
    FlightPosition(g, a.fit, a.held, q.t, &x, &y);
    return std::hypot(x - q.x, y - q.y);
  };
  DetectorArc trial = cur;
  for (const auto& q : missed) trial.samples.push_back(q);
  for (size_t kept = cur.samples.size();; --kept) {
    trial.fit_ok = false;
    arcs_.Refit(trial);  // drops a first sample the others put off the arc
    if (!trial.fit_ok || trial.samples.size() < 3) return false;
    double worst = 0;
    for (const auto& q : trial.samples) worst = std::max(worst, offset(trial, q));
    if (worst <= 3 * scene_.StartGate()) break;  // a young arc's gate (the noise maybe not measured)
    // The arc's own first samples may be the ones off (straddling the impact): drop them.
    if (kept == 0 || offset(trial, trial.samples.front()) < worst) return false;
    trial.samples.erase(trial.samples.begin());
  }
  // An arc that left the floor well after the impact that began this one is another arc
  // (after an impact this arc missed): that is for the impact to confirm, not for this arc to
  // swallow. One that left it then is this rebound, even without any of the arc's own samples
  // (its first two, smeared rising from the floor at 25 fps, 25-35 px off it).
  const FlightImpact* began = arcs_.ImpactBeforeCurrent();
  if (began && scene_.calibration().calibration.has_floor) {
    const double rise = scene_.calibration().calibration.floor_centre_px() - trial.fit.u_apex;
    const double left_floor = trial.fit.t_apex - std::sqrt(2 * std::max(0.0, rise) / g.gravity_px);
    if (left_floor > began->t + 1.5 * scene_.frame_dt()) return false;
  } else if (trial.samples.front().t > cur.samples.back().t) {
    return false;
  }
  *rebound = std::move(trial);
  return true;
}

bool ArcContinuation::YoungFallContinues(const DetectorArc& cur,
                                         const std::vector<DetectorSample>& missed,
                                         Eigen::Vector3d* fall_parabola) const {
  // Only a release arc not yet calibrated, before any impact, turning away samples that are
  // one fall: each lower than the one before it, from the arc's last sample on, falling
  // faster and faster along one parabola (within the start gate).
  if (!cur.release || scene_.calibrated() || arcs_.arcs().size() != 1 || cur.samples.empty() || missed.size() < 3)
    return false;
  std::vector<DetectorSample> fall{cur.samples.back()};
  for (const DetectorSample& q : missed) {
    if (q.t <= fall.back().t || Down(q) <= Down(fall.back())) return false;
    fall.push_back(q);
  }
  double rms = 0;
  *fall_parabola = scene_.DownParabola(fall, &rms);
  const double bend = (*fall_parabola)(2);
  // Free flight for the ball's size on some clock the file may have, not a hand's curve.
  return bend > 0 && rms <= scene_.StartGate() && scene_.SlowdownOfBend(2 * bend) > 0;
}

bool ArcContinuation::ArcContinues(const DetectorArc& cur,
                                   const std::vector<DetectorSample>& missed) const {
  // A calibrated arc long enough to measure its own bend, and every sample it turned away
  // after its last one, on one free parabola with it: each within the noise gate, the whole
  // within half of it, bent by a gravity within a quarter of the drop's (a hand's carry or a
  // lookalike is neither).
  constexpr size_t kMinArcSamples = 8;
  if (!scene_.calibrated() || !cur.fit_ok || cur.release || cur.samples.size() < kMinArcSamples ||
      missed.empty() || missed.front().t <= cur.samples.back().t)
    return false;
  std::vector<DetectorSample> run = cur.samples;
  run.insert(run.end(), missed.begin(), missed.end());
  double rms = 0;
  const Eigen::Vector3d arc = scene_.DownParabola(run, &rms);
  const double g_px = scene_.calibration().flight.globals.gravity_px;
  const double bend = 2 * arc(2);
  if (g_px <= 0 || rms > 0.5 * scene_.Gate() || std::abs(bend / g_px - 1) > 0.25) return false;
  const double t_last = run.back().t;
  for (const DetectorSample& q : missed)
    if (std::abs(Down(q) - ParabolaAt(arc, q.t - t_last)) > scene_.Gate()) return false;
  return true;
}

}  // namespace bouncefit
