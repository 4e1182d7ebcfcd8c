// Emitting apexes as they become certain, and closing a drop with its final refit.
#include "detect/apex_ledger.h"
#include "detect/detector_stats.h"

#include "detect/apex_flight_check.h"
#include "model/arc_apex.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit {

using detector_stats::FitLine;
using detector_stats::Line;

ApexLedger::ApexLedger(const ApexConfig& config, DetectorScene& scene,
                       FlightFollower& follower, DropHost& host)
    : config_(config), scene_(scene), follower_(follower), host_(host) {}

void ApexLedger::StartDrop(int first_bounce) {
  first_bounce_ = first_bounce;
  peaks_.clear();
  impacts_.clear();
  bounce0_emitted_ = false;
  ++sequence_;
}

void ApexLedger::ResetDrop() {
  peaks_.clear();
  impacts_.clear();
}

bool ApexLedger::ApexDue(const DetectorArc& arc, double t) const {
  return t >= arc.fit.t_apex + config_.emit_after_apex_frames * scene_.frame_dt();
}

bool ApexLedger::PeakEmitted(int bounce) const {
  return std::any_of(peaks_.begin(), peaks_.end(),
                     [&](const BouncePeak& p) { return p.bounce == bounce; });
}

void ApexLedger::ForgetImpact(int index) {
  impacts_.erase(std::remove_if(impacts_.begin(), impacts_.end(),
                                [&](const BounceImpact& i) { return i.index == index; }),
                 impacts_.end());
}

void ApexLedger::OnSampleKept(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  const std::vector<DetectorArc>& arcs = follower_.arcs();
  if (!bounce0_emitted_ && arcs.size() == 2 && arcs[0].held &&
      static_cast<int>(arcs[1].samples.size()) >= config_.bounce0_rising_samples) {
    host_.Recalibrate(s.utime, ev);  // the rising branch pins drag against gravity
    EmitPeak(0, s.utime, ev);
  }
  TryEmitApex(s.t, s.utime, true, ev);
}

void ApexLedger::OnImpact(int64_t utime, std::vector<DetectorEvent>& ev) {
  std::vector<DetectorArc>& arcs = follower_.arcs();
  const size_t idx = arcs.size() - 1;
  const FlightImpact* began = follower_.ImpactBeforeCurrentArc();
  if (scene_.calibrated() && began && scene_.calibration().calibration.valid()) {
    const BounceImpact bi = ToBounceImpact(*began, static_cast<int>(idx) + first_bounce_);
    impacts_.push_back(bi);
    DetectorEvent e;
    e.kind = DetectorEvent::Kind::kImpact;
    e.impact = bi;
    ev.push_back(e);
  }
  EmitUnreported(idx, utime, ev);
  if (!bounce0_emitted_ && idx == 1 && arcs[0].held &&
      static_cast<int>(arcs[1].samples.size()) >= config_.bounce0_rising_samples)
    EmitPeak(0, utime, ev);
}

void ApexLedger::EmitUnreported(size_t end, int64_t utime, std::vector<DetectorEvent>& ev) {
  const std::vector<DetectorArc>& arcs = follower_.arcs();
  if (arcs.empty() || !scene_.calibrated()) return;
  for (size_t j = arcs[0].entered ? 0 : 1; j < end && j < arcs.size(); ++j) {
    if (arcs[j].apex_emitted || !arcs[j].fit_ok) continue;
    const double h = scene_.calibration().calibration.floor_centre_px() - arcs[j].fit.u_apex;
    if (h >= scene_.MinApexPx()) EmitPeak(j, utime, ev);
  }
}

void ApexLedger::TryEmitApex(double t, int64_t utime, bool have_sample,
                             std::vector<DetectorEvent>& ev) {
  if (follower_.arcs().size() < 2 || !scene_.calibrated()) return;
  const size_t idx = follower_.arcs().size() - 1;
  DetectorArc& arc = follower_.arcs()[idx];
  if (arc.apex_emitted || arc.apex_held || !arc.fit_ok) return;
  if (arc.samples.size() < (have_sample ? 3u : 5u)) return;
  const double margin = config_.emit_after_apex_frames * scene_.frame_dt();
  if (t < arc.fit.t_apex + margin) return;
  host_.Recalibrate(utime, ev);
  if (!follower_.arcs()[idx].fit_ok || t < follower_.arcs()[idx].fit.t_apex + margin) return;
  // Rest is judged on the floor line: on the floor under the arc the shared football clip
  // shows two more hops (8 and 6 cm, beyond the 4-8 a person counts).
  const DetectorArc& rising = follower_.arcs()[idx];
  const double h = scene_.calibration().calibration.floor_centre_px() - rising.fit.u_apex;
  // Nor is a hop whose rise from its own first sample, taken just after its impact, is that
  // low, when the rise has enough samples to put that one within a sixth of the flight from the
  // floor (so a real hop rises at least 0.7 of its height from it): a ball rolling away from
  // the camera rests above the floor line of its first impacts (a tennis ball at 240 fps,
  // 8 px up the picture), where its wobble would count as hops.
  constexpr size_t kRisingSamples = 8;
  size_t before_apex = 0;
  for (const auto& q : rising.samples) before_apex += q.t <= rising.fit.t_apex;
  const bool rose_little = before_apex >= kRisingSamples &&
                           scene_.Down(rising.samples.front()) - rising.fit.u_apex < scene_.MinApexPx();
  if (h < scene_.MinApexPx() || rose_little) {
    host_.EndSequence("rest", ev);
    return;
  }
  EmitPeak(idx, utime, ev);
}

double ApexLedger::FloorUnderArcPx(size_t j, bool both) const {
  // The impacts known (imps[i] between arcs i and i + 1): a line through their contact
  // heights against time, least squares, at the apex; their mean when there are fewer than
  // three, the calibration's floor line when there are none. Live (`both` false) only impacts
  // before this apex count, except the release arc's closing one, and each weighs half as
  // much as the one after it: the floor under a ball coming towards the camera drifts down
  // the picture, faster as it comes closer, and a line held by the old impacts lags it (the
  // shared football clip's sixth rebound was 15% low); the recent contacts say where the
  // floor is now, the older ones still steady the line (docs/ACCURACY.md, "The floor under
  // each apex"). Refitted (`both` true), the arc's own two contacts weigh most and each
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
  const auto& imps = scene_.calibration().impacts;
  const double t_apex = j < follower_.arcs().size() ? follower_.arcs()[j].fit.t_apex : 0;
  const double below_max = std::max(10.0, 2 * scene_.RadiusPx());
  std::vector<double> ts, us, ws;  // times from the apex, contact heights, weights
  std::vector<size_t> taken;       // their impacts' indices
  for (size_t i = 0; i < imps.size() && i < follower_.arcs().size(); ++i) {
    if (!imps[i].ok) continue;
    if (!both && i >= j && !(j == 0 && i == 0)) continue;
    if (follower_.ArcScatter(follower_.arcs()[i]) > below_max ||
        (i + 1 < follower_.arcs().size() && follower_.ArcScatter(follower_.arcs()[i + 1]) > below_max))
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
  if (ts.empty()) return scene_.calibration().calibration.floor_centre_px();
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

void ApexLedger::EmitPeak(size_t j, int64_t utime, std::vector<DetectorEvent>& ev) {
  const Calibration& cal = scene_.calibration().calibration;
  if (j >= follower_.arcs().size() || !cal.valid() || !cal.has_floor || !follower_.arcs()[j].fit_ok) return;
  // Peaks go out in bounce order: a release height still pending goes first.
  if (j > 0 && !bounce0_emitted_) EmitPeak(0, utime, ev);
  DetectorArc& arc = follower_.arcs()[j];
  if (j == 0 && arc.entered && !EnteredApexSeen()) {
    bounce0_emitted_ = true;  // entered falling: its apex was never in view
    return;
  }
  BouncePeak p;
  p.utime = utime;
  p.sequence = sequence_;
  p.bounce = static_cast<int>(j) + first_bounce_;
  const FlightGlobals& g = scene_.calibration().flight.globals;
  double t_top = FlightTopT(arc.fit, arc.held);
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
      hs.push_back(floor_px - scene_.Down(q) + drag);
    }
    const ArcApex a = FitArcApex(ts, hs);
    if (a.ok && ts.size() >= 5 && std::abs(a.t - arc.fit.t_apex) < scene_.frame_dt()) {
      p.height_px = a.height;
      t_top = a.t;
    }
  }
  p.apex_utime = scene_.ToUtime(t_top);
  // An apex at or below the floor is no bounce (the arc was not free flight).
  if (p.height_px < scene_.MinApexPx()) {
    if (j == 0) bounce0_emitted_ = true;
    arc.apex_emitted = true;
    return;
  }
  p.height_m = p.height_px / cal.px_per_m;
  p.height_sigma_m = PictureSigmaM(arc, p.height_m);
  if (j >= 1 && config_.flight_check_sigmas > 0) {
    const ApexFlightResult f = CheckApexAgainstFlight(FlightInputFor(j, t_top, p.height_m, p.height_sigma_m));
    if (f.verdict == ApexVerdict::kHold) {
      arc.apex_held = true;
      return;
    }
    if (f.verdict == ApexVerdict::kWithhold) {
      arc.apex_held = false;
      arc.apex_emitted = true;
      return;
    }
    if (f.verdict == ApexVerdict::kFlightHeight) {
      p.height_m = f.flight_m;
      p.height_sigma_m = f.flight_sigma_m;
      p.height_px = f.flight_m * cal.px_per_m;
    }
  }
  // A bounced ball only loses height: a rebound far higher than the one before it (beyond
  // the restitution any ball has, and beyond both heights' uncertainty) was lifted or thrown
  // by a hand, and is no bounce.
  if (j >= 2 && !peaks_.empty() && peaks_.back().bounce == p.bounce - 1) {
    const BouncePeak& before = peaks_.back();
    const double sigma = std::hypot(before.height_sigma_m, p.height_sigma_m);
    if (p.height_m > config_.max_rebound_gain * before.height_m + 3 * sigma) {
      arc.apex_emitted = true;
      return;
    }
  }
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

void ApexLedger::CloseDrop(const std::string& reason, std::vector<DetectorEvent>& ev) {
  const std::vector<DetectorArc>& arcs = follower_.arcs();
  const CalibrationResult& fit = scene_.calibration();
  SequenceSummary sum;
  sum.sequence = sequence_;
  sum.first_bounce = first_bounce_;
  sum.released_from_hold = first_bounce_ == 0 && !arcs.empty() && arcs[0].held;
  sum.end_reason = reason;
  sum.peaks = peaks_;
  sum.calibration = fit.calibration;
  // Impacts from the final refit (the streamed ones saw two or three rising samples).
  for (size_t j = 0; j < fit.impacts.size() && j + 1 < arcs.size(); ++j) {
    const FlightImpact& imp = fit.impacts[j];
    if (!imp.ok || !fit.calibration.valid()) continue;
    sum.impacts.push_back(ToBounceImpact(imp, static_cast<int>(j + 1) + first_bounce_));
  }
  const Calibration& cal = fit.calibration;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool metres = scene_.calibrated() && cal.valid() && cal.has_floor;
  std::vector<double> impact_t;
  for (size_t j = 0; j + 1 < arcs.size() && j < fit.impacts.size(); ++j)
    impact_t.push_back(fit.impacts[j].ok ? fit.impacts[j].t : nan);
  for (size_t j = 0; j < arcs.size(); ++j) {
    const double top = FlightTopU(fit.flight.globals, arcs[j].fit, arcs[j].held);
    double final_m = metres && arcs[j].fit_ok ? (FloorUnderArcPx(j, true) - top) / cal.px_per_m : nan;
    // Checked against its flight as the live apex was (both sides known now, or none).
    if (j >= 1 && std::isfinite(final_m) && config_.flight_check_sigmas > 0) {
      const ApexFlightResult f = CheckApexAgainstFlight(FlightInputFor(
          j, FlightTopT(arcs[j].fit, arcs[j].held), final_m, PictureSigmaM(arcs[j], final_m)));
      if (f.verdict == ApexVerdict::kFlightHeight) final_m = f.flight_m;
      if (f.verdict == ApexVerdict::kWithhold) final_m = nan;
    }
    sum.final_height_m.push_back(final_m);
    double fh = nan;
    if (j >= 1 && j < impact_t.size()) {
      const double dt = impact_t[j] - impact_t[j - 1];
      fh = scene_.calibrator().config().g_mps2 * dt * dt / 8;
    }
    sum.flight_height_m.push_back(fh);
  }
  // Emitted peaks learn their closing impact and flight height here.
  for (auto& p : sum.peaks) {
    const auto b = static_cast<size_t>(p.bounce - first_bounce_);
    if (b < sum.flight_height_m.size()) p.flight_height_m = sum.flight_height_m[b];
    if (b < impact_t.size() && std::isfinite(impact_t[b])) p.impact_after_utime = scene_.ToUtime(impact_t[b]);
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

BounceImpact ApexLedger::ToBounceImpact(const FlightImpact& imp, int index) const {
  BounceImpact bi;
  bi.sequence = sequence_;
  bi.index = index;
  bi.utime = scene_.ToUtime(imp.t);
  bi.speed_in_mps = imp.speed_in / scene_.calibration().calibration.px_per_m;
  bi.speed_out_mps = imp.speed_out / scene_.calibration().calibration.px_per_m;
  bi.restitution = imp.speed_in > 0 ? imp.speed_out / imp.speed_in : 0;
  return bi;
}

double ApexLedger::PictureSigmaM(const DetectorArc& arc, double height_m) const {
  const Calibration& cal = scene_.calibration().calibration;
  const double rel = cal.px_per_m_sigma / cal.px_per_m;
  return std::hypot(std::hypot(arc.u_sigma, cal.floor_sigma_px) / cal.px_per_m, height_m * rel);
}

ApexFlightInput ApexLedger::FlightInputFor(size_t j, double t_apex, double picture_m,
                                           double picture_sigma_m) const {
  const CalibrationResult& cr = scene_.calibration();
  const auto& imps = cr.impacts;
  ApexFlightInput in;
  in.picture_m = picture_m;
  in.picture_sigma_m = picture_sigma_m;
  // imps[i] lies between arcs i and i + 1: arc j flies from imps[j - 1] to imps[j].
  if (j >= 1 && j - 1 < imps.size() && imps[j - 1].ok) in.rise_s = t_apex - imps[j - 1].t;
  if (j < imps.size() && j + 1 < follower_.arcs().size() && imps[j].ok) in.fall_s = imps[j].t - t_apex;
  in.time_sigma_s = config_.impact_time_sigma_frames * scene_.frame_dt();
  in.g_mps2 = scene_.calibrator().config().g_mps2;
  in.drag_per_m = cr.flight.globals.drag_per_px * cr.calibration.px_per_m;
  in.sigmas = config_.flight_check_sigmas;
  return in;
}

bool ApexLedger::EnteredApexSeen() const {
  if (follower_.arcs().empty() || !follower_.arcs()[0].entered || !follower_.arcs()[0].fit_ok) return false;
  const DetectorArc& a = follower_.arcs()[0];
  return a.fit.t_apex >= a.samples.front().t && a.fit.t_apex <= a.samples.back().t;
}

}  // namespace bouncefit
