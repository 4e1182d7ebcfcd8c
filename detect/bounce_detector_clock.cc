// The scale and the clock: the calibration refitted with the drop's arcs, the time scale
// decided (slow motion), and the closed arcs' samples judged anew on each new scale.
#include "detect/bounce_detector.h"

#include <cmath>
#include <vector>

namespace bouncefit {

void BounceDetector::Recalibrate(int64_t utime, std::vector<DetectorEvent>& ev) {
  const std::vector<DetectorArc>& arcs_now = follower_.arcs();
  CalibrationInput in;
  in.utime = utime;
  in.arcs = follower_.ArcData();
  in.radius_px = scene_.RadiusPx();
  std::vector<FlightArcParams> prev_arcs;
  bool all_fit = scene_.calibrated();
  for (const auto& a : arcs_now) {
    all_fit = all_fit && a.fit_ok;
    prev_arcs.push_back(a.fit);
  }
  FlightGlobals prev_globals;
  if (scene_.calibrated()) {
    prev_globals = scene_.calibration().flight.globals;
    in.previous_globals = &prev_globals;
    if (all_fit) in.previous_arcs = &prev_arcs;
  }
  const Calibrator& calibrator = scene_.calibrator();
  CalibrationResult res = calibrator.Calibrate(in);
  if (!res.flight.ok) return;
  // A later drop of the same camera falls with the same gravity: an arc that says otherwise
  // by far is no free flight (a hand carrying the ball) and must not replace the scale.
  const Calibration& known = scene_.calibration().calibration;
  if (scene_.calibrated() && ledger_.sequence() > scene_.calibration_sequence() &&
      known.samples >= 15 &&
      std::abs(std::log(res.calibration.gravity_px / known.gravity_px)) > std::log(1.25))
    return;
  scene_.calibration().calibration.gravity_over_size = res.calibration.gravity_over_size;
  if (!scene_.clock_decided() && arcs_now.size() >= 2) {
    const double k = scene_.DecideClock(
        res.calibration.FreeFallMeasured(calibrator.config().max_free_fall_rel_sigma),
        arcs_now.size());
    if (k > 0) {
      // The timeline is slowed: every time so far was stream time. Start again in real time.
      RescaleTime(1 / k);
      in.arcs = follower_.ArcData();
      in.previous_globals = nullptr;
      in.previous_arcs = nullptr;
      res = calibrator.Calibrate(in);
      if (!res.flight.ok) return;
    }
  }
  ApplyCalibration(std::move(res));
  // The arcs' samples judged anew on this scale; the scale again if an arc took some back.
  for (int round = 0; round < config_.readmit_rounds && follower_.ReadmitSamples(); ++round) {
    in.arcs = follower_.ArcData();
    FlightGlobals globals = scene_.calibration().flight.globals;
    std::vector<FlightArcParams> arcs;
    for (const auto& a : arcs_now) arcs.push_back(a.fit);
    in.previous_globals = &globals;
    in.previous_arcs = &arcs;
    CalibrationResult again = calibrator.Calibrate(in);
    if (!again.flight.ok) break;
    ApplyCalibration(std::move(again));
  }
  DetectorEvent e;
  e.kind = DetectorEvent::Kind::kCalibration;
  e.calibration = scene_.calibration().calibration;
  ev.push_back(e);
}

void BounceDetector::ApplyCalibration(CalibrationResult res) {
  scene_.Adopt(std::move(res), ledger_.sequence());
  follower_.TakeFits(scene_.calibration().flight);
}

void BounceDetector::RescaleTime(double k) {
  scene_.RescaleTime(k);
  start_.RescaleTime(k);
  follower_.RescaleTime(k);
}

}  // namespace bouncefit
