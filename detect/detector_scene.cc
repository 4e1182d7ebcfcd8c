// The clock, the noise, the ball's size and the calibration the detector's parts share.
#include "detect/detector_scene.h"
#include "detect/detector_stats.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {

using detector_stats::Median;

DetectorScene::DetectorScene(const SceneConfig& config, const CalibratorConfig& calibration)
    : config_(config), calibrator_(calibration) {
  sigma_ = config_.initial_noise_px;
  if (config_.time_scale > 0) {
    scale_ = config_.time_scale;
    clock_decided_ = true;
    frame_dt_ *= scale_;
  }
}

bool DetectorScene::Advance(int64_t utime, double* t) {
  if (!have_t0_) {
    have_t0_ = true;
    t0_ = utime;
    last_utime_ = utime;
  } else {
    if (utime < last_utime_)
      throw std::invalid_argument("bounce detector: observation times went backwards (" +
                                  std::to_string(utime) + " < " +
                                  std::to_string(last_utime_) + " us)");
    if (utime == last_utime_) return false;  // a duplicate frame
    frame_dts_.push_back(static_cast<double>(utime - last_utime_) * 1e-6 * scale_);
    if (frame_dts_.size() > 64) frame_dts_.erase(frame_dts_.begin());
    frame_dt_ = Median(frame_dts_);
    last_utime_ = utime;
  }
  *t = static_cast<double>(utime - t0_) * 1e-6 * scale_;
  return true;
}

void DetectorScene::Saw(const DetectorSample& s) {
  if (s.r > 0) {
    radii_.push_back(s.r);
    if (radii_.size() > 301) radii_.erase(radii_.begin());
  }
  seen_.push_back(s);
  if (seen_.size() > kSeenKept) seen_.erase(seen_.begin());
}

double DetectorScene::Gate() const {
  return std::max(config_.min_gate_px, config_.gate_sigmas * sigma_);
}

double DetectorScene::FollowGate(double v_down, double gap_frames) const {
  return Gate() + 0.02 * std::abs(v_down) * frame_dt_ * gap_frames;
}

double DetectorScene::StartGate() const {
  if (sigma_measured_) return Gate();
  const double sigma = std::max(sigma_, config_.initial_noise_radius_share * RadiusPx());
  return std::max(config_.min_gate_px, config_.gate_sigmas * sigma);
}

double DetectorScene::MinApexPx() const {
  double flight = 0;
  if (calibrated_) {
    const double t = config_.min_flight_frames * frame_dt_;
    const Calibration& cal = calibration_.calibration;
    // Gravity in pixels: the free fall's, or the scale's when the free fall measured nothing.
    const double g_px = cal.FreeFallMeasured(calibrator_.config().max_free_fall_rel_sigma)
                            ? calibration_.flight.globals.gravity_px
                            : cal.px_per_m * calibrator_.config().g_mps2;
    flight = g_px * t * t / 8;
  }
  return std::max({config_.min_apex_px, 5 * sigma_, flight});
}

double DetectorScene::RadiusPx() const { return Median(radii_); }

double DetectorScene::SizeGravityPx() const {
  if (!(calibrator_.config().ball_diameter_m > 0) || radii_.empty()) return 0;
  const double size_px_per_m = 2 * RadiusPx() / calibrator_.config().ball_diameter_m;
  return calibrator_.config().g_mps2 * size_px_per_m;
}

double DetectorScene::SlowdownOfBend(double accel_px) const {
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

double DetectorScene::SlowdownExplaining(double q, const std::vector<double>& slowdowns) const {
  const double tol = std::log1p(config_.clock_tolerance);
  for (double k : slowdowns)
    if (std::abs(std::log(q * k * k)) < tol) return k;
  return 0;
}

double DetectorScene::DecideClock(bool free_fall, size_t arcs) {
  const double q = calibration_.calibration.gravity_over_size;
  if (!(q > 0)) return 0;
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
    return k;
  }
  // Agreement as recorded (or a size that fits no clock: reported, not acted on).
  clock_decided_ = std::abs(std::log(q)) < tol || arcs >= 3;
  return 0;
}

void DetectorScene::RescaleTime(double k) {
  scale_ *= k;
  for (auto& q : seen_) q.t *= k;
  for (auto& d : frame_dts_) d *= k;
  frame_dt_ *= k;
  last_seen_t_ *= k;
  calibrated_ = false;
}

double DetectorScene::Down(const DetectorSample& s) const {
  return AlongDown(s.x, s.y, calibrated_ ? calibration_.flight.globals.roll_rad : 0.0);
}

double DetectorScene::Floor(const DetectorSample& s) const {
  return AlongFloor(s.x, s.y, calibrated_ ? calibration_.flight.globals.roll_rad : 0.0);
}

int64_t DetectorScene::ToUtime(double t) const { return t0_ + std::llround(t / scale_ * 1e6); }

Eigen::Vector3d DetectorScene::DownParabola(const std::vector<DetectorSample>& run,
                                            double* rms) const {
  const auto rows = static_cast<Eigen::Index>(run.size());
  Eigen::MatrixXd a(rows, 3);
  Eigen::VectorXd b(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const double dt = run[static_cast<size_t>(i)].t - run.back().t;
    a(i, 0) = 1;
    a(i, 1) = dt;
    a(i, 2) = dt * dt;
    b(i) = Down(run[static_cast<size_t>(i)]);
  }
  const Eigen::Vector3d c = a.colPivHouseholderQr().solve(b);
  if (rms) *rms = std::sqrt((a * c - b).squaredNorm() / static_cast<double>(rows));
  return c;
}

void DetectorScene::ForgetCalibrationOf(int sequence) {
  if (!calibrated_ || calibration_sequence_ != sequence) return;
  calibrated_ = calibrated_before_drop_;
  calibration_sequence_ = calibration_sequence_before_drop_;
  calibration_ = calibration_before_drop_;
}

bool DetectorScene::StartDropAt(const std::vector<DetectorSample>& first_arc) {
  calibrated_before_drop_ = calibrated_;
  calibration_sequence_before_drop_ = calibration_sequence_;
  calibration_before_drop_ = calibration_;
  std::vector<double> radii;
  for (const DetectorSample& q : first_arc)
    if (q.r > 0) radii.push_back(q.r);
  if (radii.size() < 3) return false;
  const double r = Median(radii);
  const double tol = std::log1p(config_.moved_size_tolerance);
  auto differs = [&](double r_known) { return r_known > 0 && std::abs(std::log(r / r_known)) > tol; };
  // The ball's size is this drop's from now on, whatever became of the calibration.
  if (differs(RadiusPx())) radii_ = radii;
  if (!calibrated_ || !differs(calibration_.calibration.radius_px)) return false;
  calibrated_ = calibrated_before_drop_ = false;
  calibration_sequence_ = calibration_sequence_before_drop_ = -1;
  calibration_ = calibration_before_drop_ = CalibrationResult{};
  return true;
}

void DetectorScene::TakeHoldNoise(double rms_px) {
  if (!sigma_measured_) sigma_ = std::max(config_.noise_floor_px, rms_px);
}

void DetectorScene::Adopt(CalibrationResult res, int sequence) {
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
  calibration_sequence_ = sequence;
  if (calibration_.flight.samples > 10) {
    sigma_ = std::max(config_.noise_floor_px, calibration_.flight.rms_px);
    sigma_measured_ = true;
  }
}

}  // namespace bouncefit
