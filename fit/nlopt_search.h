#pragma once
// The default search: a bounded derivative-free quadratic-model method (NLopt BOBYQA) over
// the continuous coefficients that matter, normalised to [0, 1].
//
// 1. Screening, in parallel on all cores: the start point and +-step along every free
//    coefficient (discrete mesh coefficients: +-one level, meshes cached by the model).
//    These are exactly BOBYQA's 2n+1 initial interpolation points, so they are paid once,
//    concurrently; they also give the heights Jacobian (uncertainty, identifiability) and
//    name the coefficients with no effect, which are left out of the search.
// 2. BOBYQA (COBYLA for a single coefficient), serially, restarted from the best point
//    while restarts gain (each restart's initial points evaluated in parallel).
// 3. Discrete coefficients: neighbouring levels tried in parallel at the optimum; a better
//    level gets one more, shorter continuous round.
// 4. What is left of the budget: local sampling around the best point
//    (fit/local_sampling.h), where the soft body's chaotic heights leave BOBYQA's quadratic
//    model nothing to follow.
#include <string>

#include "fit/fit_objective.h"
#include "fit/local_sampling.h"

namespace bouncefit {

struct NloptSearchOptions {
  double initial_step = 0.15;   // BOBYQA's initial trust radius, fraction of each range
  double xtol = 2e-3;           // stop when steps are below this (fraction of range)
  double ftol_rel = 1e-6;       // or the objective changes by less than this fraction
  double min_effect_m = 1e-6;   // +-step changing no height by more than this: no effect
  int max_active = 0;           // search only the n most sensitive coefficients; 0 = all
  bool search_discrete = true;  // try neighbouring levels of discrete coefficients
  int max_restarts = 6;         // BOBYQA restarts from the best point while they gain
  double restart_min_gain = 0.02;  // a restart must lower the objective by this fraction
  bool sample_after = true;     // spend what is left of the budget on local sampling
  LocalSamplingOptions sampling;
};

SearchResult NloptSearch(const FitProblem& problem, const CoefficientValues& start,
                         const SearchOptions& options, const NloptSearchOptions& nlopt = {});

}  // namespace bouncefit
