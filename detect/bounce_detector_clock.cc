// The scale and the clock: recalibration from the drop's arcs, and the time scale (slow motion).
#include "detect/bounce_detector.h"
#include "detect/detector_stats.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace bouncefit {

using detector_stats::LineDrift;
using detector_stats::Median;

void BounceDetector::Recalibrate(int64_t utime, std::vector<DetectorEvent>& ev) {
  CalibrationInput in;
  in.utime = utime;
  in.arcs = ArcData();
  in.radius_px = RadiusPx();
  std::vector<FlightArcParams> prev_arcs;
  bool all_fit = calibrated_;
  for (const auto& a : arcs_) {
    all_fit = all_fit && a.fit_ok;
    prev_arcs.push_back(a.fit);
  }
  FlightGlobals prev_globals;
  if (calibrated_) {
    prev_globals = calibration_.flight.globals;
    in.previous_globals = &prev_globals;
    if (all_fit) in.previous_arcs = &prev_arcs;
  }
  CalibrationResult res = calibrator_.Calibrate(in);
  if (!res.flight.ok) return;
  // A later drop of the same camera falls with the same gravity: an arc that says otherwise
  // by far is no free flight (a hand carrying the ball) and must not replace the scale.
  if (calibrated_ && sequence_ > calibration_sequence_ && calibration_.calibration.samples >= 15 &&
      std::abs(std::log(res.calibration.gravity_px / calibration_.calibration.gravity_px)) >
          std::log(1.25))
    return;
  calibration_.calibration.gravity_over_size = res.calibration.gravity_over_size;
  if (!clock_decided_ && arcs_.size() >= 2 &&
      DecideClock(res.calibration.FreeFallMeasured(config_.calibration.max_free_fall_rel_sigma))) {
    // The timeline is slowed: every time so far was stream time. Start again in real time.
    in.arcs = ArcData();
    in.previous_globals = nullptr;
    in.previous_arcs = nullptr;
    res = calibrator_.Calibrate(in);
    if (!res.flight.ok) return;
  }
  ApplyCalibration(std::move(res));
  // The arcs' samples judged anew on this scale; the scale again if an arc took some back.
  for (int round = 0; round < config_.readmit_rounds && ReadmitSamples(); ++round) {
    in.arcs = ArcData();
    FlightGlobals globals = calibration_.flight.globals;
    std::vector<FlightArcParams> arcs;
    for (const auto& a : arcs_) arcs.push_back(a.fit);
    in.previous_globals = &globals;
    in.previous_arcs = &arcs;
    CalibrationResult again = calibrator_.Calibrate(in);
    if (!again.flight.ok) break;
    ApplyCalibration(std::move(again));
  }
  DetectorEvent e;
  e.kind = DetectorEvent::Kind::kCalibration;
  e.calibration = calibration_.calibration;
  ev.push_back(e);
}

void BounceDetector::ApplyCalibration(CalibrationResult res) {
  if (!res.calibration.has_floor && calibrated_ && calibration_.calibration.has_floor) {
    // Same camera, same floor: keep the floor of an earlier drop until this one has one.
    res.calibration.has_floor = true;
    res.calibration.floor_px =
        calibration_.calibration.floor_centre_px() + res.calibration.radius_px;
    res.calibration.floor_sigma_px = calibration_.calibration.floor_sigma_px;
  }
  calibration_ = std::move(res);
  calibration_.calibration.time_scale = scale_;
  calibrated_ = true;
  calibration_sequence_ = sequence_;
  const FlightFit& flight = calibration_.flight;
  for (size_t j = 0; j < arcs_.size() && j < flight.arcs.size(); ++j) {
    arcs_[j].fit = flight.arcs[j];
    arcs_[j].fit_ok = true;
    arcs_[j].u_sigma = flight.u_apex_sigma[j];
  }
  if (flight.samples > 10) {
    sigma_ = std::max(config_.noise_floor_px, flight.rms_px);
    sigma_measured_ = true;
  }
}

bool BounceDetector::DecideClock(bool free_fall) {
  const double q = calibration_.calibration.gravity_over_size;
  if (!(q > 0)) return false;
  const double tol = std::log1p(config_.clock_tolerance);
  const double hint = config_.capture_slowdown_hint;
  // A slow-down the container announces, confirmed by the size, changes the clock; without
  // the container's word, one no wrong ball size explains, on a measured free fall only (a
  // close-up ball's few smeared frames measure none, and their scale says anything).
  std::vector<double> slowdowns;
  if (hint > 1.05)
    slowdowns = {hint};
  else if (free_fall)
    slowdowns = config_.untagged_slowdowns;
  double k = SlowdownExplaining(q, slowdowns);
  // The container's word, and a size nearer its clock than the recorded one: a ball given
  // as the nearest preset.
  if (const double off = std::abs(std::log(q * hint * hint));
      !(k > 0) && hint > 1.05 && off < std::log(config_.preset_size_error) && off < std::abs(std::log(q)))
    k = hint;
  if (k > 0) {
    clock_decided_ = true;
    RescaleTime(1 / k);
    return true;
  }
  // Agreement as recorded (or a size that fits no clock: reported, not acted on).
  clock_decided_ = std::abs(std::log(q)) < tol || arcs_.size() >= 3;
  return false;
}

double BounceDetector::SlowdownExplaining(double q, const std::vector<double>& slowdowns) const {
  const double tol = std::log1p(config_.clock_tolerance);
  for (double k : slowdowns)
    if (std::abs(std::log(q * k * k)) < tol) return k;
  return 0;
}

void BounceDetector::RescaleTime(double k) {
  scale_ *= k;
  auto scale = [k](std::vector<Sample>& v) {
    for (auto& q : v) q.t *= k;
  };
  scale(hold_);
  scale(pending_up_);
  scale(pending_off_);
  scale(rest_samples_);
  scale(seen_);
  scale(flight_seen_);
  for (auto& a : arcs_) {
    scale(a.samples);
    a.fit.t_apex *= k;
    a.fit.vw /= k;
    a.fit_ok = false;
  }
  for (auto& d : frame_dts_) d *= k;
  frame_dt_ *= k;
  last_seen_t_ *= k;
  calibrated_ = false;
}

}  // namespace bouncefit
