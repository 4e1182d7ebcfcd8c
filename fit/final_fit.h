#pragma once
// The fit session's final fit at the end of a drop: every free coefficient searched within
// its bounds with a larger budget, from where the drop's fits started (the table, or the
// previous drop's final answer; never the per-bounce updates', so the same peaks give the
// same final fit); then the heights Jacobian at the answer for the uncertainties, the
// restitution law's held coefficients (at a bound, or the preset's or the data's value along
// a flat direction), the free-running check, and the bounces' own restitution widening the
// law's sigmas.
#include <atomic>
#include <string>
#include <vector>

#include "fit/drop_problem.h"
#include "fit/fit_objective.h"
#include "fit/fit_session_config.h"
#include "fit/fit_update.h"
#include "fit/recorded_drop.h"
#include "fit/restitution_fit.h"
#include "model/ball_model.h"

namespace bouncefit {

// A final search's answer, before it is a FitUpdate.
struct FinalSearchResult {
  SearchResult result;
  FitProblem problem;                         // the answer's problem (its free coefficients)
  std::vector<HeldCoefficient> held;          // the law's coefficients the search held
  std::vector<std::vector<double>> jacobian;  // heights Jacobian at the answer (empty: none)
  int jacobian_evaluations = 0;
};

// Reads the session's models, settings, drops and problems by reference: they must outlive it.
class FinalFit {
 public:
  // `start`: where the first final fit starts; `lead_order`: the free coefficients, the most
  // influential first (the starts' Gauss-Newton rounds take the first few).
  FinalFit(const BallModel& model, const BallModel* quick_model, const FitSessionConfig& config,
           const RecordedDrop& drop, const std::vector<KeptDrop>& kept, const DropProblems& problems,
           CoefficientValues start, std::vector<std::string> lead_order);

  // Simulations Search() and Check() run at most together (what progress reads against).
  int Budget() const;
  // The searches and the Jacobian; an answer not cancelled is where the next one starts.
  FinalSearchResult Search(const CancelToken* cancel, std::atomic<int>* simulations);
  // What follows the report `u` of `s`: the held coefficients, the search's failure, the
  // free-running check, the restitution points and the sigmas they widen.
  void Check(const FinalSearchResult& s, const CancelToken* cancel, std::atomic<int>* simulations,
             FitUpdate* u) const;

 private:
  // Simulations after the search: the Jacobian and the free-running checks.
  int AfterSearchSimulations() const;
  // One start: Gauss-Newton rounds on the lead_n most influential coefficients from start_,
  // then the thorough search, within `budget` simulations.
  SearchResult StartSearch(int lead_n, int budget, const SearchOptions& options) const;
  // The restitution impact's final fit: the law's curve in two stages; *p its problem,
  // *held the law's coefficients stage 1 held.
  SearchResult RestitutionSearch(int budget, const SearchOptions& options, FitProblem* p,
                                 std::vector<HeldCoefficient>* held) const;
  // simulated_m and residual_m from one drop as `simulate` runs it, free_run_* from the
  // ensemble; the answer dropped from the safe heights.
  void CheckFreeRun(const FitProblem& problem, std::atomic<int>* simulations, FitUpdate* u) const;

  const BallModel& model_;
  const BallModel* quick_model_;
  const FitSessionConfig& config_;
  const RecordedDrop& drop_;
  const std::vector<KeptDrop>& kept_;
  const DropProblems& problems_;
  CoefficientValues start_;
  std::vector<std::string> lead_order_;
};

}  // namespace bouncefit
