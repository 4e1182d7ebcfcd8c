#pragma once
// A fit that follows a drop bounce by bounce.
//
// The session records the drop's apexes (fit/recorded_drop.h: the start apex and the heights
// r_1..r_k after it). After each, Update() refines the coefficients so that the simulated
// s_1..s_k match them (objective sum (r_i - s_i)^2 inside the coefficients' bounds),
// warm-started from the previous answer, and QuickUpdate() is the point-mass estimate
// (restitution, its speed dependence and drag), milliseconds (fit/live_updates.h).
// FinalUpdate() is the thorough fit at the end of a drop (fit/final_fit.h): every free
// coefficient, a larger budget, uncertainties from the heights Jacobian at the answer; it
// starts where the drop's fits started, so the same peaks give the same final fit; and it is
// an answer only within its gate (fit/answer_gate.h).
// Updates take a cancellation token checked between simulations: a cancelled update
// returns with `cancelled` set and its best point kept as the next warm start.
//
// Synchronous and single-threaded from the caller's view (simulations inside run on a
// thread pool); FitWorker runs it on a thread with supersede semantics.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <vector>

#include "fit/drop_problem.h"
#include "fit/final_fit.h"
#include "fit/fit_objective.h"
#include "fit/fit_session_config.h"
#include "fit/fit_update.h"
#include "fit/live_updates.h"
#include "fit/recorded_drop.h"
#include "model/ball_model.h"

namespace bouncefit {

class FitSession {
 public:
  // `model` is fitted; `quick_model` (may be null) gives QuickUpdate(). Both must outlive
  // the session. Throws std::invalid_argument for settings it does not know.
  FitSession(const BallModel& model, const BallModel* quick_model, FitSessionConfig config);

  // Starts a new drop (forgets heights; keeps the warm start).
  void Reset(int sequence);
  // Keeps the drop recorded so far (when it has a bounce to fit) for the final fits that
  // follow, fitted jointly with the next drops, then starts a new drop.
  void KeepDropAndReset(int sequence);
  int kept_drops() const { return static_cast<int>(kept_.size()); }
  // Records a peak (a later one of the same bounce replaces it: a revision) and chooses the
  // start again (RecordedDrop). Returns false (and records nothing) for a peak of another
  // sequence: call Reset() first.
  bool AddPeak(const PeakInput& peak);

  int sequence() const { return sequence_; }
  bool has_drop_height() const { return drop_.drop_height_m() > 0; }
  double drop_height_m() const { return drop_.drop_height_m(); }  // the start's height
  int start_bounce() const { return drop_.start_bounce(); }
  int bounces() const { return drop_.last_bounce(); }  // last bounce index seen
  std::vector<double> FittedHeights() const { return drop_.fitted_heights(); }  // r_1.. above the minimum height
  std::vector<double> FittedFlights() const { return drop_.fitted_flights(); }  // RecordedDrop::fitted_flights()
  bool CanFit() const { return drop_.CanFit(); }

  FitUpdate QuickUpdate();
  FitUpdate Update(const CancelToken* cancel = nullptr);
  FitUpdate FinalUpdate(const CancelToken* cancel = nullptr);
  // Simulations FinalUpdate() runs at most, everything included (what its progress reads
  // against: never past it).
  int FinalBudget() const { return final_.Budget(); }

  const CoefficientValues& warm_start() const { return live_.warm_start(); }
  const FitSessionConfig& config() const { return config_; }
  const BallModel& model() const { return model_; }
  // Simulations run by all fits so far (read from any thread: progress of a running fit).
  int simulations() const { return simulations_.load(); }

 private:
  // `r`, searched on `problem` with `model` (the fitted one or the quick one), as an update.
  FitUpdate Report(const FitProblem& problem, const SearchResult& r, bool final,
                   const std::vector<std::vector<double>>& jacobian, int extra_evals,
                   std::chrono::steady_clock::time_point t0, const BallModel& model) const;

  const BallModel& model_;
  const BallModel* quick_model_;
  const FitSessionConfig config_;
  RecordedDrop drop_;
  std::vector<KeptDrop> kept_;  // earlier drops, fitted with this one in final fits
  DropProblems problems_;
  LiveUpdates live_;
  FinalFit final_;
  int sequence_ = 0;
  int64_t last_utime_ = 0;
  std::atomic<int> simulations_{0};
};

}  // namespace bouncefit
