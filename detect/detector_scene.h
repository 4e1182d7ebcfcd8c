#pragma once
// What every part of the bounce detector reads about the camera and the ball: the clock (the
// stream's time, the frame period, real seconds per stream second), the noise the tracker's
// samples show, the ball's size in the picture, the samples seen last, and the calibration
// (scale, gravity, drag, roll, floor) with the calibrator that fits it. The parts
// (detect/drop_start.h, detect/flight_follower.h, detect/apex_ledger.h) judge samples with
// its gates; the BounceDetector that composes them refits the calibration and decides the
// clock through it.
#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "detect/calibrator.h"
#include "detect/flight_model.h"
#include "track/ball_observation.h"

namespace bouncefit {

// One frame's ball, in the scene (a hand-held camera's motion taken out), time in real
// seconds from the stream's first frame.
struct DetectorSample {
  double t = 0;
  double x = 0, y = 0;
  double r = 0;
  int64_t utime = 0;
};

// One free-flight arc of a drop and its fit (FlightArcParams under the calibration's globals).
struct DetectorArc {
  std::vector<DetectorSample> samples;
  bool held = false;
  size_t hold_samples = 0;  // held: the first samples, still in the hand
  bool release = false;  // the first arc of a drop: a fall from rest (held seen or not)
  bool entered = false;  // the first arc of a drop, not from rest: thrown, or already
                         // in flight when first seen
  bool apex_emitted = false;
  // Its apex disagreed with the flight time since the impact before it: it waits for the
  // impact after it, then both sides of the flight judge it (detect/apex_flight_check.h).
  bool apex_held = false;
  int late_drops = 0;  // first samples dropped later than straddle_frames after the impact
  bool fit_ok = false;
  FlightArcParams fit;
  double u_sigma = 0;
};

// The gates, the noise and the clock (fields of BounceDetectorConfig).
struct SceneConfig {
  double gate_sigmas = 6;       // a sample this many noise sigmas off its arc is not on it
  double min_gate_px = 0.8;     // ... and at least this far
  double noise_floor_px = 0.05; // lower bound on the noise estimate
  double initial_noise_px = 0.3;  // until the first fit measures it
  // Whether the first samples make an arc: until then, the noise is taken as at least this
  // share of the ball's radius (a ball 150 px across, smeared at 24 fps, is not located to
  // 0.3 px; every length in the picture scales with its size).
  double initial_noise_radius_share = 0.01;
  double min_apex_px = 1.0;     // rebounds lower than this (or 5 noise sigmas) mean rest
  // ... or lower than a flight this many frames long can show (g T^2 / 8: 1.97 cm at 30 fps,
  // 1.2 mm at 120 fps; a hop of fewer samples has no measurable apex). A 2 cm hop at 30 fps
  // lasts 3.83 frames: its three or four samples, the scale known, fix its apex.
  double min_flight_frames = 3.8;
  // The clock: real seconds per second of the frames' timestamps. 0 = decide: as recorded,
  // unless the container says the file is slowed (capture_slowdown_hint = capture fps /
  // stored fps) and the ball's known size confirms that factor: gravity measured on a
  // timeline slowed s times is s^2 too small, so the free-fall scale over the size scale is
  // 1/s^2. The container's word needs less of the size than the size alone would: the slowed
  // clock is taken when it explains the two scales better than the recorded one and within
  // preset_size_error (a ball given as the nearest preset: a 5 cm ball as a tennis ball's
  // 6.7). A size that disagrees by any other factor (a ball of another size than given)
  // changes nothing but the report...
  double time_scale = 0;
  double capture_slowdown_hint = 1;
  double clock_tolerance = 0.3;  // the two scales agree within this fraction
  double preset_size_error = 2;  // ... or within this factor, with the container's word
  // ... unless the container says nothing and the disagreement is a phone's slow motion that
  // no ball given with the wrong preset explains: the presets' diameters span 6x (40 to
  // 239 mm), a timeline slowed 4x disagrees 16x, 8x 64x (a slow-motion file re-encoded, its
  // capture rate lost).
  std::vector<double> untagged_slowdowns = {4, 8};
  // A later drop whose ball is this much larger or smaller in the picture (its first arc's
  // median radius against the one the calibration used) is at another distance from the
  // camera (the ball rolled towards or away from it between drops): the earlier drop's scale
  // and floor line do not hold there, and the drop calibrates itself as a first one does. A
  // change of s in size moves the floor line by about s times the camera's height.
  double moved_size_tolerance = 0.03;
};

class DetectorScene {
 public:
  DetectorScene(const SceneConfig& config, const CalibratorConfig& calibration);

  // The clock: takes the frame's capture time; false for a duplicate frame (same time).
  // Throws std::invalid_argument when time goes backwards. *t: real seconds from the first.
  bool Advance(int64_t utime, double* t);
  // A usable sample: its radius joins the ball's size, it joins the recent samples.
  void Saw(const DetectorSample& s);

  // A sample this far off an arc is not on it, px.
  double Gate() const;
  // How far a sample may lie off an arc whose model moves at v_down px/s there, gap_frames
  // after the arc's last sample: the noise gate, plus 2% of the travel (a model a little off
  // in speed is a little off in place).
  double FollowGate(double v_down, double gap_frames = 1) const;
  // Gate() for the fit of an arc's first samples, before the noise is measured: at least a
  // share of the ball's radius (SceneConfig::initial_noise_radius_share).
  double StartGate() const;
  // The ball's radius as seen so far (median of the recent detections), px; 0 before any.
  double RadiusPx() const;
  // The lowest apex that is a bounce, px: the configured floor, 5 noise sigmas, and the
  // height of a flight min_flight_frames long.
  double MinApexPx() const;
  // Free fall at the ball's size, px/s^2 on the real clock (0: size not known).
  double SizeGravityPx() const;
  // The slow-down of the file's clock on which a start's bend (px/s^2 on the file's clock) is
  // free flight for the ball's size: 1, the container's, or an untagged one; 0: none (a hand's
  // curve). 1 when no size is given.
  double SlowdownOfBend(double accel_px) const;
  // The slow-down among `slowdowns` that explains a free-fall scale q times the ball size's
  // (a timeline slowed k times reads gravity k^2 too weak), within the clock's tolerance; 0:
  // none.
  double SlowdownExplaining(double q, const std::vector<double>& slowdowns) const;
  // Decides the clock from the calibration just fitted to `arcs` arcs (free_fall: its scale
  // rests on the free fall, not on the ball's size alone). The slow-down found, or 0 when the
  // clock stays as recorded; a slow-down asks the caller to rescale every time it holds
  // (RescaleTime) and fit again.
  double DecideClock(bool free_fall, size_t arcs);
  // Times multiplied by k (the clock found slowed): the scene's own, and the calibration
  // dropped (it was fitted in stream time).
  void RescaleTime(double k);

  // Coordinates along true down and along the floor (the calibration's roll; 0 before it).
  double Down(const DetectorSample& s) const;
  double Floor(const DetectorSample& s) const;
  int64_t ToUtime(double t) const;
  // Down(t) of the samples as c0 + c1 dt + c2 dt^2, dt from the last sample's time, and the
  // fit's RMS residual (px) when asked.
  Eigen::Vector3d DownParabola(const std::vector<DetectorSample>& run,
                               double* rms = nullptr) const;

  // A drop starts with these samples (its first arc): when the ball's size there says it is
  // at another distance from the camera than the calibration's drop was
  // (SceneConfig::moved_size_tolerance), the calibration is forgotten and the ball's size
  // starts again from these samples. True when it was.
  bool StartDropAt(const std::vector<DetectorSample>& first_arc);
  // The drop `sequence` ended having emitted no apex: it was no drop (a hand's lift taken for
  // an arc), and a calibration fitted to its arcs goes back to the one before it.
  void ForgetCalibrationOf(int sequence);
  // A hold measured the noise before any fit did.
  void TakeHoldNoise(double rms_px);
  // Takes a calibration fitted to the drop `sequence`'s arcs: scale, floor and noise.
  void Adopt(CalibrationResult res, int sequence);

  const Calibrator& calibrator() const { return calibrator_; }
  bool calibrated() const { return calibrated_; }
  const CalibrationResult& calibration() const { return calibration_; }
  CalibrationResult& calibration() { return calibration_; }
  int calibration_sequence() const { return calibration_sequence_; }
  bool clock_decided() const { return clock_decided_; }
  double scale() const { return scale_; }
  double frame_dt() const { return frame_dt_; }
  double sigma() const { return sigma_; }
  bool sigma_measured() const { return sigma_measured_; }
  int64_t last_utime() const { return last_utime_; }
  double last_seen_t() const { return last_seen_t_; }
  void set_last_seen_t(double t) { last_seen_t_ = t; }
  const SceneConfig& config() const { return config_; }
  static constexpr size_t kSeenKept = 32;
  // The last samples seen, whatever became of them, in time order.
  const std::vector<DetectorSample>& seen() const { return seen_; }

 private:
  SceneConfig config_;
  Calibrator calibrator_;
  bool have_t0_ = false;
  int64_t t0_ = 0;
  int64_t last_utime_ = 0;
  double scale_ = 1;            // real seconds per stream second
  bool clock_decided_ = false;
  std::vector<double> frame_dts_;  // real seconds
  double frame_dt_ = 1.0 / 120;
  double sigma_ = 0.3;
  bool sigma_measured_ = false;
  double last_seen_t_ = 0;
  std::vector<double> radii_;
  std::vector<DetectorSample> seen_;
  bool calibrated_ = false;
  int calibration_sequence_ = -1;  // the drop the current calibration comes from
  CalibrationResult calibration_;
  // The calibration as it was when the current drop started (ForgetCalibrationOf).
  bool calibrated_before_drop_ = false;
  int calibration_sequence_before_drop_ = -1;
  CalibrationResult calibration_before_drop_;
};

}  // namespace bouncefit
