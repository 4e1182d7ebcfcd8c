// The detector's state machine: config check, per-frame dispatch (waiting, flight, rest).
// How a drop starts, flies, is clocked and emits its peaks: bounce_detector_*.cc.
#include "detect/bounce_detector.h"
#include "detect/detector_stats.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {

using detector_stats::LineDrift;
using detector_stats::Median;

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
  if (fall_start_samples < 4) return fail("a fall start needs >= 4 samples");
  if (arc_start_samples < 4) return fail("an arc start needs >= 4 samples");
  if (!(straddle_frames >= 0) || !std::isfinite(straddle_frames))
    return fail("straddle frames must be >= 0");
  if (!(off_arc_radius_share >= 0) || !std::isfinite(off_arc_radius_share))
    return fail("off-arc radius share must be >= 0");
  if (max_late_drops < 0) return fail("max late drops must be >= 0");
  if (impact_confirm_samples < 1) return fail("impact confirmation needs >= 1 sample");
  if (bounce0_rising_samples < 1) return fail("bounce 0 needs >= 1 rising sample");
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
    : config_(Checked(config)), calibrator_(config.calibration) {
  sigma_ = config_.initial_noise_px;
  if (config_.time_scale > 0) {
    scale_ = config_.time_scale;
    clock_decided_ = true;
    frame_dt_ *= scale_;
  }
}

double BounceDetector::Gate() const {
  return std::max(config_.min_gate_px, config_.gate_sigmas * sigma_);
}

double BounceDetector::FollowGate(double v_down, double gap_frames) const {
  return Gate() + 0.02 * std::abs(v_down) * frame_dt_ * gap_frames;
}

double BounceDetector::StartGate() const {
  if (sigma_measured_) return Gate();
  const double sigma = std::max(sigma_, config_.initial_noise_radius_share * RadiusPx());
  return std::max(config_.min_gate_px, config_.gate_sigmas * sigma);
}

double BounceDetector::MinApexPx() const {
  double flight = 0;
  if (calibrated_) {
    const double t = config_.min_flight_frames * frame_dt_;
    const Calibration& cal = calibration_.calibration;
    // Gravity in pixels: the free fall's, or the scale's when the free fall measured nothing.
    const double g_px = cal.FreeFallMeasured(config_.calibration.max_free_fall_rel_sigma)
                            ? calibration_.flight.globals.gravity_px
                            : cal.px_per_m * config_.calibration.g_mps2;
    flight = g_px * t * t / 8;
  }
  return std::max({config_.min_apex_px, 5 * sigma_, flight});
}

double BounceDetector::UnseenReleaseMaxS(double bend_slowdown) const {
  // Before the clock is decided a slowed file's seconds may be `slow-down` times too long.
  const double slow =
      clock_decided_ ? 1.0 : std::max(config_.capture_slowdown_hint, bend_slowdown);
  return std::max(config_.unseen_release_max_s * slow, 2 * frame_dt_);
}

double BounceDetector::RadiusPx() const { return Median(radii_); }

double BounceDetector::SizeGravityPx() const {
  if (!(calibrator_.config().ball_diameter_m > 0) || radii_.empty()) return 0;
  const double size_px_per_m = 2 * RadiusPx() / calibrator_.config().ball_diameter_m;
  return calibrator_.config().g_mps2 * size_px_per_m;
}

double BounceDetector::SlowdownOfBend(double accel_px) const {
  const double g_px = SizeGravityPx();  // px/s^2, real time
  if (!(g_px > 0)) return 1;
  // Free flight bends at g in the size's px/m: within 4x (a ball given with the wrong preset),
  // on the file's clock or (clock undecided) on the container's slowed one, not 50x less.
  auto within_4x = [&](double k) {
    const double expected = g_px / (k * k);
    return accel_px > expected / 4 && accel_px < expected * 4;
  };
  if (within_4x(1)) return 1;
  if (clock_decided_) return 0;
  const double hint = config_.capture_slowdown_hint;
  if (hint > 1.05) return within_4x(hint) ? hint : 0;
  // A file that does not say it is slowed may be a phone's slow motion all the same
  // (DecideClock): bending at g / k^2 as closely as the clock's tolerance asks.
  return SlowdownExplaining(accel_px / g_px, config_.untagged_slowdowns);
}

double BounceDetector::Down(const Sample& s) const {
  return AlongDown(s.x, s.y, calibrated_ ? calibration_.flight.globals.roll_rad : 0.0);
}

double BounceDetector::Floor(const Sample& s) const {
  return AlongFloor(s.x, s.y, calibrated_ ? calibration_.flight.globals.roll_rad : 0.0);
}

int64_t BounceDetector::ToUtime(double t) const { return t0_ + std::llround(t / scale_ * 1e6); }

std::vector<FlightArcData> BounceDetector::ArcData() const {
  std::vector<FlightArcData> out;
  for (const auto& a : arcs_) {
    FlightArcData d;
    d.held_before_apex = a.held;
    for (const auto& s : a.samples) d.samples.push_back({s.t, s.x, s.y});
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<DetectorEvent> BounceDetector::Push(const BallObservation& o) {
  std::vector<DetectorEvent> ev;
  if (!have_t0_) {
    have_t0_ = true;
    t0_ = o.utime;
    last_utime_ = o.utime;
  } else {
    if (o.utime < last_utime_)
      throw std::invalid_argument("bounce detector: observation times went backwards (" +
                                  std::to_string(o.utime) + " < " +
                                  std::to_string(last_utime_) + " us)");
    if (o.utime == last_utime_) return ev;  // a duplicate frame
    frame_dts_.push_back(static_cast<double>(o.utime - last_utime_) * 1e-6 * scale_);
    if (frame_dts_.size() > 64) frame_dts_.erase(frame_dts_.begin());
    frame_dt_ = Median(frame_dts_);
    last_utime_ = o.utime;
  }
  const double t = static_cast<double>(o.utime - t0_) * 1e-6 * scale_;
  const bool usable = o.found && std::isfinite(o.cx) && std::isfinite(o.cy);
  if (!usable) {
    if (phase_ == Phase::kFlight) {
      if (t - last_seen_t_ > config_.lost_s)
        EndSequence("lost", ev);
      else
        TryEmitApex(t, o.utime, false, ev);
    }
    if (phase_ == Phase::kWaiting && !hold_.empty() && t - hold_.back().t > config_.lost_s)
      hold_.clear();
    return ev;
  }
  Sample s;
  s.t = t;
  // In the scene, not on the sensor: a hand-held camera's motion taken out.
  s.x = o.cx - o.camera_dx;
  s.y = o.cy - o.camera_dy;
  s.r = o.radius_px > 0 ? o.radius_px : 0.5 * std::min(o.w, o.h);
  s.utime = o.utime;
  if (s.r > 0) {
    radii_.push_back(s.r);
    if (radii_.size() > 301) radii_.erase(radii_.begin());
  }
  seen_.push_back(s);
  if (seen_.size() > kSeenKept) seen_.erase(seen_.begin());
  if (phase_ == Phase::kFlight && t - last_seen_t_ > config_.lost_s) EndSequence("lost", ev);
  last_seen_t_ = t;
  switch (phase_) {
    case Phase::kWaiting: OnWaiting(s, ev); break;
    case Phase::kFlight:
      if (flight_seen_.size() < kFlightSeenKept) flight_seen_.push_back(s);
      OnFlight(s, ev);
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

void BounceDetector::OnWaiting(const Sample& s, std::vector<DetectorEvent>& ev) {
  hold_.push_back(s);
  while (!hold_.empty() && hold_.front().t < s.t - 1.0) hold_.erase(hold_.begin());
  if (!ReleasedFromHold(s, ev) && !FallFromUnseenRelease(s, ev)) ArcFromUnseenStart(s, ev);
}

void BounceDetector::OnRest(const Sample& s, std::vector<DetectorEvent>& ev) {
  const double thr = std::max(config_.release_px, Gate());
  if (rest_samples_.empty()) {
    rest_samples_.push_back(s);
    return;
  }
  std::vector<double> ru, rw;
  for (const auto& r : rest_samples_) {
    ru.push_back(Down(r));
    rw.push_back(Floor(r));
  }
  const bool moved =
      std::abs(Down(s) - Median(ru)) > thr || std::abs(Floor(s) - Median(rw)) > thr;
  if (!moved) {
    rest_moves_ = 0;
    if (rest_samples_.size() < 30) rest_samples_.push_back(s);
    return;
  }
  if (++rest_moves_ >= 3) {
    // Picked up (or kicked): wait for the next hold and release.
    phase_ = Phase::kWaiting;
    hold_.clear();
    rest_samples_.clear();
    rest_moves_ = 0;
    OnWaiting(s, ev);
  }
}

}  // namespace bouncefit
