// The detector's state machine: config check, per-frame dispatch (waiting, flight, rest),
// a drop's start and end. The calibration's refit and the clock: bounce_detector_clock.cc.
#include "detect/bounce_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {

bool BounceDetectorConfig::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!calibration.IsValid(error)) return false;
  if (!(emit_after_apex_frames >= 0)) return fail("emit after apex must be >= 0 frames");
  if (!(gate_sigmas > 0) || !(min_gate_px > 0)) return fail("gates must be > 0");
  if (!(scale_gate_sigmas >= 0)) return fail("scale gate sigmas must be >= 0");
  if (!(noise_floor_px > 0) || !(initial_noise_px > 0)) return fail("noise must be > 0 px");
  if (!(initial_noise_radius_share >= 0 && initial_noise_radius_share < 0.5))
    return fail("initial noise share of the radius must be in [0, 0.5)");
  if (!(release_px > 0)) return fail("release distance must be > 0 px");
  if (!(min_apex_px >= 0)) return fail("minimum apex must be >= 0 px");
  if (!(min_flight_frames >= 0)) return fail("minimum flight must be >= 0 frames");
  if (!(unseen_release_max_s >= 0)) return fail("unseen release time must be >= 0 s");
  if (!(lost_s > 0)) return fail("lost time must be > 0 s");
  if (!(hold_window_s >= 0)) return fail("hold window must be >= 0 s");
  if (!(max_hold_drift > 0)) return fail("hold drift must be > 0");
  if (!(time_scale >= 0) || !std::isfinite(time_scale)) return fail("time scale must be >= 0");
  if (!(capture_slowdown_hint > 0)) return fail("capture slow-down hint must be > 0");
  if (!(clock_tolerance > 0 && clock_tolerance < 1))
    return fail("clock tolerance must be in (0, 1)");
  if (!(preset_size_error >= 1 + clock_tolerance) || !std::isfinite(preset_size_error))
    return fail("preset size error must be >= 1 + clock tolerance");
  for (double k : untagged_slowdowns)
    if (!(k > 1) || !std::isfinite(k)) return fail("untagged slow-downs must be > 1");
  if (!(moved_size_tolerance > 0) || !std::isfinite(moved_size_tolerance))
    return fail("moved size tolerance must be > 0");
  if (fall_start_samples < 4) return fail("a fall start needs >= 4 samples");
  if (arc_start_samples < 4) return fail("an arc start needs >= 4 samples");
  if (!(straddle_frames >= 0) || !std::isfinite(straddle_frames))
    return fail("straddle frames must be >= 0");
  if (!(off_arc_radius_share >= 0) || !std::isfinite(off_arc_radius_share))
    return fail("off-arc radius share must be >= 0");
  if (max_late_drops < 0) return fail("max late drops must be >= 0");
  if (impact_confirm_samples < 1) return fail("impact confirmation needs >= 1 sample");
  if (!(impact_time_sigma_frames > 0)) return fail("impact time sigma must be > 0 frames");
  if (!(flight_check_sigmas >= 0)) return fail("flight check sigmas must be >= 0");
  if (bounce0_rising_samples < 1) return fail("bounce 0 needs >= 1 rising sample");
  if (!(max_rebound_gain >= 1)) return fail("max rebound gain must be >= 1");
  return true;
}

namespace {
BounceDetectorConfig Checked(BounceDetectorConfig c) {
  std::string error;
  if (!c.IsValid(&error)) throw std::invalid_argument("bounce detector: " + error);
  return c;
}
}  // namespace

BounceDetector::BounceDetector(BounceDetectorConfig config)
    : config_(Checked(std::move(config))),
      scene_(config_, config_.calibration),
      start_(config_, scene_),
      follower_(config_, scene_, *this),
      ledger_(config_, scene_, follower_, *this) {}

std::vector<DetectorEvent> BounceDetector::Push(const BallObservation& o) {
  std::vector<DetectorEvent> ev;
  double t = 0;
  if (!scene_.Advance(o.utime, &t)) return ev;  // a duplicate frame
  const bool usable = CentrePlaced(o);
  if (!usable) {
    if (phase_ == Phase::kFlight) {
      if (t - scene_.last_seen_t() > config_.lost_s)
        EndSequence("lost", ev);
      else
        ledger_.TryEmitApex(t, o.utime, false, ev);
    }
    if (phase_ == Phase::kWaiting) start_.ForgetStaleHold(t, config_.lost_s);
    return ev;
  }
  DetectorSample s;
  s.t = t;
  // In the scene, not on the sensor: a hand-held camera's motion taken out.
  s.x = o.cx - o.camera_dx;
  s.y = o.cy - o.camera_dy;
  s.r = o.radius_px > 0 ? o.radius_px : 0.5 * std::min(o.w, o.h);
  s.utime = o.utime;
  scene_.Saw(s);
  if (phase_ == Phase::kFlight && t - scene_.last_seen_t() > config_.lost_s) EndSequence("lost", ev);
  scene_.set_last_seen_t(t);
  switch (phase_) {
    case Phase::kWaiting: OnWaiting(s, ev); break;
    case Phase::kFlight:
      follower_.Saw(s);
      follower_.OnFlight(s, ev);
      break;
    case Phase::kRest: OnRest(s, ev); break;
  }
  return ev;
}

std::vector<DetectorEvent> BounceDetector::Finish() {
  std::vector<DetectorEvent> ev;
  if (phase_ == Phase::kFlight) EndSequence("end of stream", ev);
  return ev;
}

void BounceDetector::OnWaiting(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  if (auto found = start_.OnWaiting(s)) StartSequence(std::move(*found), s, ev);
}

void BounceDetector::OnRest(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  if (!start_.PickedUp(s)) return;
  // Picked up (or kicked): wait for the next hold and release.
  phase_ = Phase::kWaiting;
  OnWaiting(s, ev);
}

void BounceDetector::StartSequence(DropStartFound start, const DetectorSample& s,
                                   std::vector<DetectorEvent>& ev) {
  start.arc.release = !start.arc.entered;
  // The ball rolled towards or away from the camera since the last drop: that drop's scale
  // and floor are not this one's.
  scene_.StartDropAt(start.arc.samples);
  ledger_.StartDrop(start.first_bounce);
  follower_.Start(std::move(start.arc));
  phase_ = Phase::kFlight;
  if (scene_.calibrated()) {
    DetectorArc& first = follower_.arcs()[0];
    follower_.RefitArc(first);
    // Scale and floor known from an earlier drop: the release height is known now.
    const Calibration& cal = scene_.calibration().calibration;
    if (first.release && cal.valid() && cal.has_floor) {
      ledger_.EmitPeak(0, s.utime, ev);
      ledger_.MarkBounce0Emitted();
    }
  }
}

void BounceDetector::EndSequence(const std::string& reason, std::vector<DetectorEvent>& ev) {
  const std::vector<DetectorArc>& arcs = follower_.arcs();
  if (ledger_.sequence() >= 0 && !arcs.empty()) {
    // A last look with every arc: final heights, flight-time heights, restitution.
    if (arcs.size() >= 2) Recalibrate(scene_.last_utime(), ev);
    // A release not seen held waits for the first rebound's apex; it has none (too low).
    if (!ledger_.bounce0_emitted() && arcs.size() >= 2 && !arcs[0].held)
      ledger_.EmitPeak(0, scene_.last_utime(), ev);
    ledger_.CloseDrop(reason, ev);
    if (ledger_.peaks().empty()) scene_.ForgetCalibrationOf(ledger_.sequence());
  }
  follower_.Reset();
  ledger_.ResetDrop();
  start_.Reset();
  phase_ = reason == "rest" ? Phase::kRest : Phase::kWaiting;
}

void BounceDetector::OnSampleKept(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  ledger_.OnSampleKept(s, ev);
}

void BounceDetector::OnNoSample(double t, int64_t utime, std::vector<DetectorEvent>& ev) {
  ledger_.TryEmitApex(t, utime, false, ev);
}

bool BounceDetector::ApexDue(const DetectorArc& arc, double t) const {
  return ledger_.ApexDue(arc, t);
}

void BounceDetector::OnImpactConfirmed(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  Recalibrate(s.utime, ev);
  std::vector<DetectorArc>& arcs = follower_.arcs();
  // The drop's first arc was taken for a throw (the ball seen before it, where the arc leads
  // back to). Seen down at the floor just before it, the ball came from an impact the arc's
  // start did not show (its first samples, smeared, off it): its apex is bounce 1.
  if (arcs.size() == 2 && arcs[0].entered && ledger_.first_bounce() == 0 &&
      ledger_.peaks().empty() && start_.EnteredFromTheFloor())
    ledger_.set_first_bounce(1);
  // Taken for an arc from out of view, it was a fall from a hold the tracker missed: its
  // vertex is the release, bounce 0 (a still ball found only once it fell).
  if (arcs.size() == 2 && ledger_.peaks().empty() && start_.EnteredFallWasAnUnseenRelease(arcs[0])) {
    arcs[0].entered = false;
    arcs[0].release = true;
    ledger_.set_first_bounce(0);
  }
  ledger_.OnImpact(s.utime, ev);
}

}  // namespace bouncefit
