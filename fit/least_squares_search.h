#pragma once
// Levenberg-Marquardt on the heights residuals r_i - s_i, bounded by projection onto the
// normalised box, Jacobian by forward differences evaluated in parallel. For cheap, smooth
// models (the point mass): the quick physical estimate. Leaves the Jacobian at the answer
// in the result (normalised units) for the uncertainties.
#include "fit/fit_objective.h"

namespace bouncefit {

struct LeastSquaresOptions {
  double fd_step = 1e-5;        // forward-difference step, fraction of each range
  int max_iterations = 60;
  double initial_lambda = 1e-3;
  double min_relative_gain = 1e-12;
};

SearchResult LeastSquaresSearch(const FitProblem& problem, const CoefficientValues& start,
                                const SearchOptions& options, const LeastSquaresOptions& ls = {});

}  // namespace bouncefit
