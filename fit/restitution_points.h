#pragma once
// Restitution measured bounce by bounce, and whether the bounces and the drops tell one
// story. A core with no I/O.
//
// Apex h_{i-1} -> apex h_i is one impact: the ball falls from rest through h_{i-1}, hits the
// floor at v, leaves at u and rises to h_i. With quadratic drag (c = rho Cd A / 2m, per m)
//   v^2 = (g/c)(1 - exp(-2 c h_{i-1})),  u^2 = (g/c)(exp(2 c h_i) - 1),  e = u / v,
// and without it e = sqrt(h_i / h_{i-1}). The ratio of two heights needs no scale: a
// wrong px/m moves every e only through the drag term.
//
// One ball on one floor has one curve e(v). The points of each drop scatter about it by
// their heights' uncertainty and by what real impacts add (spin, the spot on the floor);
// several drops of that ball (another height, another clip) sit on the same curve within
// that scatter, or the drops disagree: one of them measured something else.
#include <string>
#include <vector>

namespace bouncefit {

struct RestitutionPoint {
  int drop = 0;          // the drop it belongs to (0, 1, ... in the order given)
  int bounce = 0;        // the rebound it ends in, numbered as its drop numbers it
  double speed_mps = 0;  // impact speed
  double e = 0;          // rebound speed / impact speed
  double sigma = 0;      // from the two heights' uncertainties
};

// A drop's points: apexes_m[0] is its start (the release, or the first apex in view) and
// bounce start_bounce, the others its rebounds in order; sigmas_m the same length (0:
// unknown; each taken at most default_sigma_m: the scale's part cancels in a ratio).
// drag_per_m is c above (0: no drag).
std::vector<RestitutionPoint> MeasureRestitution(const std::vector<double>& apexes_m,
                                                 const std::vector<double>& sigmas_m,
                                                 double drag_per_m, int drop, int start_bounce = 0,
                                                 double default_sigma_m = 0.002);

struct RestitutionConsistencyOptions {
  // Speed at which each drop's e is quoted (0: the median impact speed of the points).
  double reference_mps = 0;
  // Drops disagree when their offsets' chi-square exceeds its (1 - this) quantile.
  double false_alarm = 1e-3;
  // A point this many of its sigmas (scatter included) off its drop's line is named.
  double outlier_sigmas = 3.5;
  // What real impacts scatter at least (spin, the spot on the floor), in e: a drop of few
  // bounces cannot measure it, and heights timed by sound to 0.1 ms would claim none.
  double min_scatter = 0.01;
};

struct RestitutionConsistency {
  int points = 0, drops = 0;
  double reference_mps = 0;
  // e = e0 - k v through every point (each drop its own offset: e0 is their weighted mean).
  double e0 = 0, k = 0;
  double sigma_e0 = 0, sigma_k = 0;  // standard errors, the scatter and the drops' spread included
  // What the impacts scatter beyond their heights' uncertainty (RMS, in e).
  double scatter = 0;
  // Per drop: e at reference_mps from its own points, and its standard error.
  std::vector<double> drop_e, drop_e_sigma;
  double chi2_drops = 0;  // of the drops' offsets about their mean, drops - 1 degrees of freedom
  bool drops_agree = true;
  // One line each: a point far off its drop's line, or above 1 (energy gained).
  std::vector<std::string> suspect;
};

// points from MeasureRestitution for each drop (drop indices 0..drops-1, each with points).
RestitutionConsistency CheckRestitution(const std::vector<RestitutionPoint>& points,
                                        const RestitutionConsistencyOptions& options = {});

// Why drops that disagree are no answer, in one line with each drop's e.
std::string DropsDisagreement(const RestitutionConsistency& r);

}  // namespace bouncefit
