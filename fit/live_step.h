#pragma once
// The per-bounce update when time is short: one damped Gauss-Newton step on the heights
// residuals, every simulation of a round run at once. Round 1: the warm start and one
// forward step per coefficient (the Jacobian); round 2: the step and fractions of it
// (a parallel line search). Two rounds of simulation time on as many cores as coefficients
// plus one, whatever the budget; the best point seen wins (never worse than the start).
#include "fit/fit_objective.h"

namespace bouncefit {

struct LiveStepOptions {
  double fd_step = 0.02;     // forward-difference step, fraction of each range
  double damping = 1e-3;     // Levenberg-Marquardt damping relative to diag(J^T J)
  double max_step = 0.25;    // largest move per coefficient, fraction of its range
  int rounds = 1;            // Gauss-Newton rounds (each: Jacobian batch + line batch)
};

SearchResult LiveStep(const FitProblem& problem, const CoefficientValues& start,
                      const SearchOptions& options, const LiveStepOptions& live = {});

}  // namespace bouncefit
