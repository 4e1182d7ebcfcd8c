#pragma once
// The soft ball's restitution curve in two stages (docs/MODEL.md, "the restitution
// law"). A recorded drop measures restitution at a few impact speeds: apex r_{i-1} -> r_i
// is one impact at about sqrt(2 g r_{i-1}), drag aside. That curve is what carries over to
// another drop height, so it is fitted first and on its own:
//  1. the point mass (restitution e0, its loss per m/s k, drag Cd) on the recorded heights:
//     smooth and milliseconds;
//  2. the soft ball with the restitution law (rebound_restitution, _per_mps, drag), started
//     from stage 1, Levenberg-Marquardt with differences wide enough to step over what is
//     left of the chaos, each coefficient bounded near stage 1's value; bounce i simulated
//     from the recorded apex i-1 (multiple shooting) or one free drop.
// What Bullet's other coefficients do (the contact's length, the ball's squash) is left to
// the timing stage (fit/flight_time_fit.h) and the rest of the final fit.
#include <cmath>

#include "fit/fit_objective.h"

namespace bouncefit {

struct RestitutionFitOptions {
  bool segments = true;      // stage 2: multiple shooting (else one free drop)
  int point_mass_evaluations = 200;  // stage 1 (point-mass runs: microseconds each)
  int max_evaluations = 40;  // stage 2 simulations (a segment evaluation counts once)
  double fd_step = 0.05;     // stage 2 finite differences, fraction of each narrowed range
  // Stage 2 ranges around stage 1's values: e0 +- this, k +- this (>= 0), Cd x [1/f, f].
  double restitution_range = 0.08;
  double slope_range = 0.04;
  double drag_factor = 1.6;
  // Stage 1's honesty, drag first, then the speed slope (restitution itself is always
  // fitted), each time the fit redone without the one held: a coefficient the data put at
  // its bound (no drag, no slope) stays at that bound, an answer with a one-sided
  // uncertainty; one the heights cannot determine (its uncertainty above this fraction of
  // its range, or degenerate with the others: a flat direction) holds the ball preset's
  // value if that fits as well (within the heights' measurement), else the data's own value.
  // Never more coefficients than recorded heights.
  double measurement_sigma_m = 0.002;
  double max_sigma_fraction = 0.25;
  double pinned_fraction = 1e-3;  // within this fraction of the range from a bound: pinned
};

// A law coefficient stage 1 did not leave free, and what it holds.
struct HeldCoefficient {
  enum class Kind {
    kBound,   // the data put it at its bound: an answer (sigma one-sided, into the range)
    kPreset,  // the data cannot tell; the ball preset's value fits as well
    kData,    // the data cannot tell, but the preset's value fits worse: the data's value
    kTimed,   // the heights cannot tell the drag; the first fall's duration does (sigma)
  };
  std::string name;  // the soft ball's name
  Kind kind = Kind::kPreset;
  double value = 0;
  // kBound: how far into its range one sigma of the heights allows; kTimed: its standard
  // uncertainty from the fall's timing.
  double sigma = 0;
  std::string why;             // one line
  std::string bound;           // kBound: "lower" or "upper"
};

struct RestitutionFit {
  SearchResult point_mass;  // stage 1 (point-mass coefficient names)
  SearchResult soft;        // stage 2: every soft-ball coefficient in `values`
  std::vector<HeldCoefficient> held;
};

// The drag at which the point mass, released at rest from the problem's drop height, meets
// the floor after problem.start_fall_s, and its standard uncertainty from
// start_fall_sigma_s. NaN (both) when the fall is not timed, or no drag in the coefficient's
// range comes within 2 sigma of it (not a fall from rest: a throw, a misplaced apex time).
struct TimedDrag {
  double value = std::nan("");
  double sigma = std::nan("");
};
TimedDrag DragFromFall(const FitProblem& problem, const BallModel& point_mass,
                       const CoefficientValues& at, const CoefficientSpec& drag);

// The soft ball's name for a point-mass coefficient of the law (restitution ->
// rebound_restitution, restitution_per_mps -> rebound_restitution_per_mps,
// drag_coefficient -> drag).
std::string SoftLawName(const std::string& point_mass_name);

// `soft` is the soft ball's problem (recorded heights, drop, fixed coefficients: the start);
// its `free` is ignored. `point_mass` is the point-mass model. Simulations count against
// options.max_evaluations per stage and options.simulations.
RestitutionFit FitRestitutionCurve(const FitProblem& soft, const BallModel& point_mass,
                                   const SearchOptions& options,
                                   const RestitutionFitOptions& fit = {});

// The soft ball's coefficients that express the point mass's (e0, k, Cd) on top of `values`,
// with what would push the ball besides the law and the air off (damping, pressure, volume
// conservation).
CoefficientValues WithRestitutionLaw(CoefficientValues values, double restitution,
                                     double restitution_per_mps, double drag);

}  // namespace bouncefit
