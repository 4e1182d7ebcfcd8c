#pragma once
// A free-running drop judged as an ensemble (the soft ball is chaotic in its coefficients: docs/MODEL.md;
// multiple shooting and common random numbers, as for any chaotic simulator): the same coefficients dropped
// from the release height plus tiny offsets, turned by tiny angles about the vertical, with
// the same offsets for every coefficient set (common random numbers), so nearby sets compare
// smoothly. The mean per bounce is the prediction, the spread its honest error bar.
#include <cstdint>
#include <string>
#include <vector>

#include "model/ball_model.h"

namespace bouncefit {

struct DropEnsembleOptions {
  int members = 8;                  // perturbed runs (member 0 is the unperturbed drop)
  double height_jitter_m = 1e-4;    // release heights uniform in +- this
  double turn_jitter_rad = 0.05;    // turns about the vertical uniform in +- this
  uint32_t seed = 14;               // the common random numbers
  int threads = 0;                  // parallel runs; 0 = all cores
};

struct DropEnsemble {
  bool ok = false;
  std::string failure;                   // the first member's failure, when one failed
  std::vector<double> mean_m;            // per bounce, over the members that made it
  std::vector<double> sd_m;              // sample standard deviation, same bounces
  std::vector<double> single_m;          // member 0: the drop exactly as asked
  std::vector<std::vector<double>> runs; // every member's heights
  int simulations = 0;
};

// Bounce i is reported while at least half of the members made it. Any member that fails
// (diverges) fails the ensemble: a set that diverges near a drop is not a safe answer.
DropEnsemble SimulateDropEnsemble(const BallModel& model, const CoefficientValues& values,
                                  const SimulationOptions& drop,
                                  const DropEnsembleOptions& options = {});

// Safety: "" when the ball, dropped from each of these heights, runs until
// its bounces fall below min_bounce_m (or 6 s + 4 s/m) without diverging; else "diverges dropped from
// H m (reason)" for the first that does. The drops run in parallel. max_bounces > 0: a short
// check, each drop ends after that many bounces (the hardest impacts come first).
// min_bounce_m: hops lower than this end a drop unchecked (a big ball's hops of a tenth of
// its diameter or less are contact chatter, its measured apexes noisy by a millimetre).
std::string UnsafeDrop(const BallModel& model, const CoefficientValues& values,
                       const std::vector<double>& drops_m, int threads = 0,
                       int max_bounces = 0, double min_bounce_m = 0.01);

}  // namespace bouncefit
