#pragma once
// Pixel-to-metre calibration of a static camera from the ball's own free flight, with no
// ruler in the scene:
//  - scale: the fitted acceleration of the centre in px/s^2 divided by g is px/m (air drag
//    is fitted with it, see detect/flight_model.h);
//  - roll: the direction of that acceleration in the image;
//  - floor line: where the falling and rising branches around each impact meet (or where the
//    ball rests), plus the ball radius;
//  - a cross-check against the ball's known diameter, and explicit overrides: a user px/m
//    or the drop height (the release height in px over the given metres).
// Time is an input; nothing here reads a clock or prints.
#include <cstdint>
#include <string>
#include <vector>

#include "detect/flight_model.h"

namespace bouncefit {

// Core-side twin of bouncefit::calibration_t, plus what the detector needs besides.
struct Calibration {
  int64_t utime = 0;          // capture time of the last frame used, microseconds
  double px_per_m = 0;        // image scale used for metres
  double px_per_m_sigma = 0;  // its standard uncertainty
  double roll_rad = 0;        // angle of true down from the image +y axis (down = (sin, cos))
  double roll_sigma_rad = 0;
  double floor_px = 0;        // ball-bottom coordinate along true down at contact, px
  double floor_sigma_px = 0;
  std::string method;         // "free-fall", "drop-height", "user", "ball-diameter"
  int samples = 0;            // frames it rests on

  // Beyond calibration_t:
  bool has_floor = false;
  double gravity_px = 0;       // fitted G, px/s^2
  double drag_per_px = 0;      // fitted quadratic drag k, 1/px (drag acceleration k v^2)
  double free_fall_px_per_m = 0;  // G / g, whatever the method
  double free_fall_sigma = 0;     // its standard uncertainty, px/m
  double radius_px = 0;        // ball radius used to turn centres into ball bottoms
  double diameter_ratio = 0;   // measured / given ball diameter (0: no diameter given)
  double rms_px = 0;           // residual of the free-flight fit, px per coordinate
  double time_scale = 1;       // real seconds per second of the frames' timestamps
  // Free-fall scale over the ball-size scale, on the clock used (0: no size given); 1/s^2
  // on a timeline slowed s times and read as real.
  double gravity_over_size = 0;

  bool valid() const { return px_per_m > 0; }
  // The free fall gave a scale known to within max_rel_sigma of itself.
  bool FreeFallMeasured(double max_rel_sigma) const {
    return free_fall_px_per_m > 0 && free_fall_sigma <= max_rel_sigma * free_fall_px_per_m;
  }
  // Ball-centre coordinate along true down at contact (floor_px - radius_px).
  double floor_centre_px() const { return floor_px - radius_px; }
};

struct CalibratorConfig {
  double g_mps2 = 9.81;
  double ball_diameter_m = 0;  // > 0: cross-check (and fallback scale) from the ball size
  double px_per_m = 0;         // > 0: the user's scale is used for metres
  double drop_height_m = 0;    // > 0: scale = release height (px) / this
  bool fit_drag = true;        // false: no air drag in the free-flight model
  bool fit_release_speed = true;  // false: a held ball is always let go from rest
  int max_arcs = 8;            // the first arcs of a drop carry the information
  int min_arc_samples = 4;     // shorter arcs do not enter the scale fit
  // A free-fall scale less certain than this (standard uncertainty over the scale) measures
  // nothing: arcs of a few smeared samples, or a lock on something else. The ball's size,
  // when given, is the scale then.
  double max_free_fall_rel_sigma = 0.25;

  // Ceres style: false with a one-line reason.
  bool IsValid(std::string* error) const;
};

// The free-flight arcs of one drop, in order: arc i+1 starts at the impact ending arc i.
// Arc 0 may be a release from rest (held_before_apex).
struct CalibrationInput {
  int64_t utime = 0;
  std::vector<FlightArcData> arcs;
  double radius_px = 0;              // ball radius seen in the image (median), px
  std::vector<double> rest_u_px;     // centre along true down while resting (if seen)
  // Warm start: the previous fit's globals and arcs (arcs may be fewer than now).
  const FlightGlobals* previous_globals = nullptr;
  const std::vector<FlightArcParams>* previous_arcs = nullptr;
};

struct CalibrationResult {
  bool ok = false;
  Calibration calibration;
  FlightFit flight;                    // fitted globals and every arc's apex
  std::vector<FlightImpact> impacts;   // impacts[i] between arcs i and i+1
  std::string problem;                 // why not ok
};

class Calibrator {
 public:
  // Throws std::invalid_argument with a one-line message for an invalid config.
  explicit Calibrator(CalibratorConfig config);

  // Fits every arc (all of them get apexes; only the first max_arcs with enough samples
  // decide G, drag and roll). Never throws.
  CalibrationResult Calibrate(const CalibrationInput& input) const;

  // Arc apexes with the globals held fixed (cheap: for the arc in progress).
  FlightFit FitArcs(const std::vector<FlightArcData>& arcs, const FlightGlobals& globals,
                    const std::vector<FlightArcParams>& initial) const;

  const CalibratorConfig& config() const { return config_; }

 private:
  CalibratorConfig config_;
};

}  // namespace bouncefit
