#pragma once
// The fit session's per-bounce updates: after each apex, the point mass's quick estimate
// (milliseconds) and the fitted model's update on the most sensitive coefficients, each
// warm-started from the last answer and cut short by a cancellation token between
// simulations (the best point so far is kept as the next warm start).
#include <atomic>
#include <string>
#include <vector>

#include "fit/drop_problem.h"
#include "fit/fit_objective.h"
#include "fit/fit_session_config.h"
#include "fit/recorded_drop.h"
#include "model/ball_model.h"

namespace bouncefit {

// A per-bounce search: its problem and its answer.
struct LiveStepResult {
  FitProblem problem;
  SearchResult result;
};

// Reads the session's models, settings, drop and problems by reference: they must outlive it.
class LiveUpdates {
 public:
  // The warm start is the model's defaults overridden by config.start; the quick model's,
  // its defaults.
  LiveUpdates(const BallModel& model, const BallModel* quick_model, const FitSessionConfig& config,
              const RecordedDrop& drop, const DropProblems& problems);

  // The quick model's estimate: restitution alone from one or two bounces, then its speed
  // dependence, then drag.
  LiveStepResult Quick();
  // The fitted model's update (simulations counted in *simulations).
  LiveStepResult Update(const CancelToken* cancel, std::atomic<int>* simulations);
  // A final fit's answer (`r` at the heights Jacobian `jacobian` over `free`): the next warm
  // start, and the most sensitive coefficients first.
  void TakeFinal(const SearchResult& r, const std::vector<std::vector<double>>& jacobian,
                 const std::vector<CoefficientSpec>& free);

  const CoefficientValues& warm_start() const { return current_; }
  // The free coefficients, the ones to search first first.
  const std::vector<std::string>& order() const { return order_; }

 private:
  const BallModel& model_;
  const BallModel* quick_model_;
  const FitSessionConfig& config_;
  const RecordedDrop& drop_;
  const DropProblems& problems_;
  CoefficientValues current_;     // warm start of the model
  CoefficientValues quick_current_;
  bool quick_fitted_ = false;     // quick_current_ holds a Quick() answer
  std::vector<std::string> order_;
};

}  // namespace bouncefit
