#pragma once
// Free flight of a ball seen by a static camera, in pixels: gravity G (px/s^2) along the
// true-down image direction d = (sin roll, cos roll), quadratic air drag k (1/px, the
// deceleration is k v^2), and the closed-form vertical solution of that ODE (ln cosh on the
// way down, ln sec on the way up). Each arc is described by its apex: time, position along
// true down (u) and along the floor (w), and a constant horizontal speed.
//
// FitFlight fits G, k and roll jointly with every arc's apex by Levenberg-Marquardt: the
// free-fall calibration of the detector (the fitted acceleration in px/s^2 divided by g is
// px/m, and its direction is the camera roll), with drag modelled rather than ignored
// (drag is up to 40% of g for a ping-pong ball at 5 m/s).
#include <vector>

namespace bouncefit {

// One sample of the ball centre: time in seconds (any epoch), image position in pixels.
struct FlightSample {
  double t = 0;
  double x = 0, y = 0;
};

struct FlightArcData {
  std::vector<FlightSample> samples;
  // true: the ball was held still before its apex (a release from rest): before the apex
  // time it stays at the apex position instead of following a rising branch.
  bool held_before_apex = false;
};

struct FlightArcParams {
  double t_apex = 0;  // s
  double u_apex = 0;  // px along true down (d . p)
  double w_apex = 0;  // px along the floor (e . p, e = (cos roll, -sin roll))
  double vw = 0;      // px/s along the floor
  // Held arcs: the release, s after the vertex (0: from rest; > 0 pushed down by the hand, the
  // vertex a virtual one above it; < 0 tossed up into the vertex). Until then the ball stays
  // where the flight passes at the release.
  double lead_s = 0;
};

struct FlightGlobals {
  double gravity_px = 0;  // G, px/s^2
  double drag_per_px = 0; // k, 1/px (deceleration k v^2)
  double roll_rad = 0;
};

// Displacement along true down (px, >= 0) from the apex after tau seconds (tau > 0 falling,
// tau < 0 rising back in time), and the velocity along true down (px/s).
double FlightDrop(double gravity_px, double drag_per_px, double tau);
double FlightVelocityDown(double gravity_px, double drag_per_px, double tau);

// Model position of one sample time on an arc.
void FlightPosition(const FlightGlobals& g, const FlightArcParams& a, bool held_before_apex,
                    double t, double* x, double* y);

struct FlightFitOptions {
  bool fit_gravity = true;  // false: gravity_px is held at its initial value
  bool fit_drag = true;     // false: drag_per_px is held at its initial value
  bool fit_roll = true;     // false: roll is held at its initial value
  bool fit_horizontal_speed = true;  // false: vw held (e.g. arcs with one or two samples)
  // true: a held arc's release speed (FlightArcParams::lead_s) is fitted; false: held
  // (from rest, unless the initial arcs say otherwise).
  bool fit_release_lead = false;
  int max_iterations = 60;
};

struct FlightFit {
  bool ok = false;
  FlightGlobals globals;
  std::vector<FlightArcParams> arcs;
  double gravity_sigma = 0, drag_sigma = 0, roll_sigma = 0;
  std::vector<double> u_apex_sigma;  // per arc, px
  double rms_px = 0;  // per coordinate
  int samples = 0;
  int iterations = 0;
};

// The highest point of an arc's flight along true down (px) and its time (s): the vertex, or
// the release of a held arc pushed down past it.
double FlightTopU(const FlightGlobals& g, const FlightArcParams& a, bool held_before_apex);
double FlightTopT(const FlightArcParams& a, bool held_before_apex);

// Initial arc parameters from a quadratic fit of each arc's samples along the given roll
// (for arcs with at least 3 samples; shorter arcs get their mean position).
FlightArcParams InitialArcParams(const FlightArcData& arc, const FlightGlobals& g);

// Fits the free parameters starting from `initial` (globals) and `initial_arcs` (one per arc;
// empty: InitialArcParams). Never throws; ok = false when the problem is degenerate.
FlightFit FitFlight(const std::vector<FlightArcData>& arcs, const FlightGlobals& initial,
                    const std::vector<FlightArcParams>& initial_arcs,
                    const FlightFitOptions& options);

// Where the falling branch of arc a meets the rising branch of the following arc b (an
// impact): time (s), position along true down (px) and both speeds (px/s, magnitudes).
struct FlightImpact {
  bool ok = false;
  double t = 0;
  double u = 0;
  double speed_in = 0, speed_out = 0;
};
FlightImpact IntersectArcs(const FlightGlobals& g, const FlightArcParams& a,
                           const FlightArcParams& b);

// Coordinates of an image point along true down and along the floor, for a roll angle.
double AlongDown(double x, double y, double roll_rad);
double AlongFloor(double x, double y, double roll_rad);

}  // namespace bouncefit
