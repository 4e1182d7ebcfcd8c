#pragma once
// The seed paper's serial search (section 4.2): one coefficient at a time, in the paper's
// priority order; a finite difference gives the direction that lowers sum (r_i - s_i)^2;
// the step doubles while it keeps improving, then a bisection-like refinement narrows the
// bracket around the best value. Sweeps repeat while a sweep still improves. Serial: one
// simulation at a time, as in the paper.
#include <vector>

#include "fit/fit_objective.h"

namespace bouncefit {

struct PaperSearchOptions {
  double initial_step = 0.05;     // finite-difference step, fraction of a coefficient's range
  double min_bracket = 0.004;     // refinement stops at this bracket width (fraction of range)
  int max_sweeps = 3;             // passes over all coefficients
  double min_sweep_gain = 1e-3;   // a sweep must lower the objective by this fraction to go on
};

// Starts from `start` (missing free coefficients take their defaults).
SearchResult PaperSearch(const FitProblem& problem, const CoefficientValues& start,
                         const SearchOptions& options, const PaperSearchOptions& paper = {});

}  // namespace bouncefit
