#pragma once
// The search problems of a fit session: the recorded drop (and the drops kept before it) as
// a FitProblem over chosen coefficients from a chosen point, how long its simulations run,
// and the safe drops the final fit's candidates must survive.
#include <vector>

#include "fit/fit_objective.h"
#include "fit/fit_session_config.h"
#include "fit/recorded_drop.h"
#include "model/ball_model.h"

namespace bouncefit {

// Reads the session's model, settings and drops by reference: they must outlive it.
class DropProblems {
 public:
  DropProblems(const BallModel& model, const FitSessionConfig& config, const RecordedDrop& drop,
               const std::vector<KeptDrop>& kept);

  // `free` searched from `at`. live: the per-bounce problem (the drop in progress only, its
  // simulations stopped sooner); else the final fits' (the kept drops too). Throws
  // std::logic_error when the drop has no bounce to fit yet.
  FitProblem Make(const std::vector<CoefficientSpec>& free, const CoefficientValues& at,
                  bool live = false) const;
  // `p` rejecting candidate answers that diverge from the settings' safe drops (when the
  // settings check them inside the search).
  FitProblem WithSafety(FitProblem p) const;

 private:
  const BallModel& model_;
  const FitSessionConfig& config_;
  const RecordedDrop& drop_;
  const std::vector<KeptDrop>& kept_;
};

}  // namespace bouncefit
