// Emitting apexes as they become certain, and closing a drop with its final refit.
#include "detect/bounce_detector.h"
#include "detect/detector_stats.h"

#include "model/arc_apex.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {

using detector_stats::FitLine;
using detector_stats::Line;
using detector_stats::Median;

void BounceDetector::TryEmitApex(double t, int64_t utime, bool have_sample,
                                 std::vector<DetectorEvent>& ev) {
  if (arcs_.size() < 2 || !calibrated_) return;
  const size_t idx = arcs_.size() - 1;
  Arc& arc = arcs_[idx];
  if (arc.apex_emitted || !arc.fit_ok) return;
  if (arc.samples.size() < (have_sample ? 3u : 5u)) return;
  const double margin = config_.emit_after_apex_frames * frame_dt_;
  if (t < arc.fit.t_apex + margin) return;
  Recalibrate(utime, ev);
  if (!arcs_[idx].fit_ok || t < arcs_[idx].fit.t_apex + margin) return;
  // Rest is judged on the floor line: on the floor under the arc the shared football clip
  // shows two more hops (8 and 6 cm, beyond the 4-8 a person counts).
  const double h = calibration_.calibration.floor_centre_px() - arcs_[idx].fit.u_apex;
  if (h < MinApexPx()) {
    EndSequence("rest", ev);
    return;
  }
  EmitPeak(idx, utime, ev);
}

double BounceDetector::FloorUnderArcPx(size_t j, bool both) const {
  // The impacts known (imps[i] between arcs i and i + 1): a line through their contact
  // heights against time, least squares, at the apex; their mean when there are fewer than
  // three, the calibration's floor line when there are none. Live (`both` false) only impacts
  // before this apex count, except the release arc's closing one, and each weighs half as
  // much as the one after it: the floor under a ball coming towards the camera drifts down
  // the picture, faster as it comes closer, and a line held by the old impacts lags it (the
  // shared football clip's sixth rebound was 15% low); the recent contacts say where the
  // floor is now, the older ones still steady the line (docs/ACCURACY.md, "The floor under a
  // live apex"). Refitted (`both` true), the arc's own two contacts weigh most and each
  // impact further from them half as much as the one before: one line through all of them
  // cuts across a drift that quickens (the football's seventh rebound 7% low).
  //
  // An impact more than a ball's diameter below the impacts before it is not a contact: two
  // arcs that are not consecutive (a short hop between them unseen, 4 frames at 30 fps), each
  // extrapolated past its own impact, cross well under the floor. It says nothing of it.
  // Nor does one made by an arc whose samples lie a diameter off it (RMS): that arc was not the
  // ball's flight (a "hold" that was something else, then the ball's streak at 20 fps) and meets
  // the next one anywhere, in mid-air. Taken first, such an impact would have every later, lower
  // contact judged under the floor.
  const auto& imps = calibration_.impacts;
  const double t_apex = j < arcs_.size() ? arcs_[j].fit.t_apex : 0;
  const double below_max = std::max(10.0, 2 * RadiusPx());
  std::vector<double> ts, us, ws;  // times from the apex, contact heights, weights
  std::vector<size_t> taken;       // their impacts' indices
  for (size_t i = 0; i < imps.size() && i < arcs_.size(); ++i) {
    if (!imps[i].ok) continue;
    if (!both && i >= j && !(j == 0 && i == 0)) continue;
    if (ArcScatter(arcs_[i]) > below_max ||
        (i + 1 < arcs_.size() && ArcScatter(arcs_[i + 1]) > below_max))
      continue;
    if (!us.empty()) {
      Line before = FitLine(ts, us, {});
      if (ts.size() < 3) before.slope = 0;
      if (imps[i].u - before.At(imps[i].t - t_apex) > below_max) continue;
    }
    ts.push_back(imps[i].t - t_apex);
    us.push_back(imps[i].u);
    taken.push_back(i);
  }
  // None before the apex to go by: those after it, before the calibration's mean of them all.
  if (ts.empty() && !both) return FloorUnderArcPx(j, true);
  if (ts.empty()) return calibration_.calibration.floor_centre_px();
  if (!both && j >= 1)
    for (size_t i = 0; i < ts.size(); ++i) ws.push_back(std::ldexp(1.0, -static_cast<int>(ts.size() - 1 - i)));
  if (both)
    for (size_t i : taken) {
      // Arc j lies between impacts j - 1 and j.
      const int away = i + 1 <= j ? static_cast<int>(j - 1 - i) : static_cast<int>(i - j);
      ws.push_back(std::ldexp(1.0, -away));
    }
  Line line = FitLine(ts, us, ws);
  // Two impacts' slope is mostly their noise (basketball): their mean then.
  if (ts.size() < 3) line.slope = 0;
  return line.At(0);  // the line at t_apex
}

void BounceDetector::EmitPeak(size_t j, int64_t utime, std::vector<DetectorEvent>& ev) {
  const Calibration& cal = calibration_.calibration;
  if (j >= arcs_.size() || !cal.valid() || !cal.has_floor || !arcs_[j].fit_ok) return;
  // Peaks go out in bounce order: a release height still pending goes first.
  if (j > 0 && !bounce0_emitted_) EmitPeak(0, utime, ev);
  Arc& arc = arcs_[j];
  if (j == 0 && arc.entered && !EnteredApexSeen()) {
    bounce0_emitted_ = true;  // entered falling: its apex was never in view
    return;
  }
  BouncePeak p;
  p.utime = utime;
  p.sequence = sequence_;
  p.bounce = static_cast<int>(j) + first_bounce_;
  const FlightGlobals& g = calibration_.flight.globals;
  p.apex_utime = ToUtime(FlightTopT(arc.fit, arc.held));
  const double floor_px = FloorUnderArcPx(j, false);
  p.height_px = floor_px - FlightTopU(g, arc.fit, arc.held);
  // The release arc's apex is its fitted vertex (seen held, or extrapolated from the fall).
  if (config_.use_arc_apex && !arc.release) {
    // Heights above the floor with the drag's departure from a parabola removed.
    std::vector<double> ts, hs;
    for (const auto& q : arc.samples) {
      const double tau = q.t - arc.fit.t_apex;
      if (std::abs(tau) > config_.arc_apex_window_s) continue;
      const double drag = FlightDrop(g.gravity_px, g.drag_per_px, tau) - 0.5 * g.gravity_px * tau * tau;
      ts.push_back(q.t);
      hs.push_back(floor_px - Down(q) + drag);
    }
    const ArcApex a = FitArcApex(ts, hs);
    if (a.ok && ts.size() >= 5 && std::abs(a.t - arc.fit.t_apex) < frame_dt_) {
      p.height_px = a.height;
      p.apex_utime = ToUtime(a.t);
    }
  }
  // An apex at or below the floor is no bounce (the arc was not free flight).
  if (p.height_px < MinApexPx()) {
    if (j == 0) bounce0_emitted_ = true;
    arc.apex_emitted = true;
    return;
  }
  p.height_m = p.height_px / cal.px_per_m;
  const double rel = cal.px_per_m_sigma / cal.px_per_m;
  p.height_sigma_m = std::hypot(std::hypot(arc.u_sigma, cal.floor_sigma_px) / cal.px_per_m,
                                p.height_m * rel);
  for (const auto& imp : impacts_)
    if (imp.index == p.bounce) p.impact_before_utime = imp.utime;
  p.emitted_utime = utime;
  arc.apex_emitted = true;
  if (j == 0) bounce0_emitted_ = true;
  peaks_.push_back(p);
  DetectorEvent e;
  e.kind = DetectorEvent::Kind::kPeak;
  e.peak = p;
  ev.push_back(e);
}

void BounceDetector::EndSequence(const std::string& reason, std::vector<DetectorEvent>& ev) {
  if (sequence_ >= 0 && !arcs_.empty()) {
    // A last look with every arc: final heights, flight-time heights, restitution.
    if (arcs_.size() >= 2) Recalibrate(last_utime_, ev);
    // A release not seen held waits for the first rebound's apex; it has none (too low).
    if (!bounce0_emitted_ && arcs_.size() >= 2 && !arcs_[0].held) EmitPeak(0, last_utime_, ev);
    SequenceSummary sum;
    sum.sequence = sequence_;
    sum.first_bounce = first_bounce_;
    sum.end_reason = reason;
    sum.peaks = peaks_;
    sum.calibration = calibration_.calibration;
    // Impacts from the final refit (the streamed ones saw two or three rising samples).
    for (size_t j = 0; j < calibration_.impacts.size() && j + 1 < arcs_.size(); ++j) {
      const FlightImpact& imp = calibration_.impacts[j];
      if (!imp.ok || !calibration_.calibration.valid()) continue;
      sum.impacts.push_back(ToBounceImpact(imp, static_cast<int>(j + 1) + first_bounce_));
    }
    const Calibration& cal = calibration_.calibration;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const bool metres = calibrated_ && cal.valid() && cal.has_floor;
    std::vector<double> impact_t;
    for (size_t j = 0; j + 1 < arcs_.size() && j < calibration_.impacts.size(); ++j)
      impact_t.push_back(calibration_.impacts[j].ok ? calibration_.impacts[j].t : nan);
    for (size_t j = 0; j < arcs_.size(); ++j) {
      const double top = FlightTopU(calibration_.flight.globals, arcs_[j].fit, arcs_[j].held);
      sum.final_height_m.push_back(
          metres && arcs_[j].fit_ok ? (FloorUnderArcPx(j, true) - top) / cal.px_per_m : nan);
      double fh = nan;
      if (j >= 1 && j < impact_t.size()) {
        const double dt = impact_t[j] - impact_t[j - 1];
        fh = calibrator_.config().g_mps2 * dt * dt / 8;
      }
      sum.flight_height_m.push_back(fh);
    }
    // Emitted peaks learn their closing impact and flight height here.
    for (auto& p : sum.peaks) {
      const auto b = static_cast<size_t>(p.bounce - first_bounce_);
      if (b < sum.flight_height_m.size()) p.flight_height_m = sum.flight_height_m[b];
      if (b < impact_t.size() && std::isfinite(impact_t[b])) p.impact_after_utime = ToUtime(impact_t[b]);
    }
    if (sum.impacts.size() >= 2) {
      double sx = 0, sy = 0, sxx = 0, sxy = 0;
      const double n = static_cast<double>(sum.impacts.size());
      for (const auto& i : sum.impacts) {
        sx += i.speed_in_mps;
        sy += i.restitution;
        sxx += i.speed_in_mps * i.speed_in_mps;
        sxy += i.speed_in_mps * i.restitution;
      }
      const double den = n * sxx - sx * sx;
      if (std::abs(den) > 1e-12) {
        sum.restitution_slope_per_mps = (n * sxy - sx * sy) / den;
        sum.restitution_intercept = (sy - sum.restitution_slope_per_mps * sx) / n;
      }
    }
    summaries_.push_back(sum);
    DetectorEvent e;
    e.kind = DetectorEvent::Kind::kSequenceEnd;
    e.reason = reason;
    ev.push_back(e);
  }
  arcs_.clear();
  flight_seen_.clear();
  pending_up_.clear();
  pending_off_.clear();
  last_far_.reset();
  misses_ = 0;
  peaks_.clear();
  impacts_.clear();
  hold_.clear();
  rest_samples_.clear();
  rest_moves_ = 0;
  phase_ = reason == "rest" ? Phase::kRest : Phase::kWaiting;
}

BounceImpact BounceDetector::ToBounceImpact(const FlightImpact& imp, int index) const {
  BounceImpact bi;
  bi.sequence = sequence_;
  bi.index = index;
  bi.utime = ToUtime(imp.t);
  bi.speed_in_mps = imp.speed_in / calibration_.calibration.px_per_m;
  bi.speed_out_mps = imp.speed_out / calibration_.calibration.px_per_m;
  bi.restitution = imp.speed_in > 0 ? imp.speed_out / imp.speed_in : 0;
  return bi;
}

}  // namespace bouncefit
