#pragma once
// The last stage of the default search, for the soft body's chaotic heights.
//
// The soft-body heights are a smooth function of the coefficients plus a deterministic but
// rough "chaos" term (docs/MODEL.md: a few ppm move later bounces by percent). A quadratic
// model (BOBYQA) finds the smooth basin, then its trust region collapses on the roughness.
// From there the best use of simulations is to sample around the best point: a (1+lambda)
// evolution strategy, one batch of `lambda` Gaussian steps at a time on all cores, moving
// to the best candidate when it beats the incumbent, widening the step after a success and
// narrowing it after a failure. Every point it returns reproduces its heights to the bit
// (same model, same time step), so a lucky draw of the chaos is a valid answer, not noise.
#include <cstdint>
#include <vector>

#include "fit/fit_objective.h"

namespace bouncefit {

struct LocalSamplingOptions {
  double initial_sigma = 0.02;  // Gaussian step, fraction of each coefficient's range
  double min_sigma = 1e-4;      // the step never shrinks below this
  double max_sigma = 0.15;      // nor grows above this
  double grow = 1.5;            // step factor after a batch that improved
  double shrink = 0.7;          // after a batch that did not
  int batch = 0;                // candidates per batch; 0 = max(4, 2 x threads)
  int max_batches = 0;          // 0 = until the objective's budget is used or it stops
  uint32_t seed = 1;            // fixed: the same inputs give the same answer
};

// Samples the `active` coordinates of the normalised point *x (others stay) until the
// objective stops (budget, target, cancellation) or max_batches; *x ends at the best point.
// Returns the number of batches that improved.
int LocalSampling(FitObjective& f, const std::vector<size_t>& active, std::vector<double>* x,
                  const LocalSamplingOptions& options = {});

}  // namespace bouncefit
