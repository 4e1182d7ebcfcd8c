#pragma once
// The paper's objective, sum_i (r_i - s_i)^2 over recorded vs simulated bounce heights, as
// a function of the free coefficients normalised to [0, 1] inside their bounds.
//
// Shared by the searches: counts simulations, caches points already evaluated (so a search
// that revisits a point, or evaluates in parallel what another step asks for next, pays
// once), keeps the best point seen, records the best-so-far residual after every
// simulation (for benchmarks), and stops on a cancellation token or an evaluation budget.
// Evaluations are checked for cancellation between simulations, never inside one.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "model/ball_model.h"

namespace bouncefit {

// Cooperative cancellation: set by whoever supersedes a fit, polled between simulations.
class CancelToken {
 public:
  void Cancel() { cancelled_.store(true); }
  bool cancelled() const { return cancelled_.load(); }

 private:
  std::atomic<bool> cancelled_{false};
};

// What a search works on: a model, the coefficients it may change (with their bounds), the
// values of all others, how to simulate, and the recorded heights r_1..r_k.
struct FitProblem {
  const BallModel* model = nullptr;
  std::vector<CoefficientSpec> free;  // searched, in priority order
  CoefficientValues fixed;            // every other coefficient (defaults when missing)
  SimulationOptions simulation;
  std::vector<double> recorded_m;     // r_1..r_k, metres
  // Multiple shooting (Bock 1981; Baake et al., Phys. Rev. A 45, 1992): bounce i
  // is simulated as its own segment, the ball released at rest from the recorded apex i-1
  // (the drop height for i = 1), and s_i is that segment's first bounce. Errors cannot
  // compound from bounce to bounce, so the objective does not follow one draw of the chaos.
  // false: one free-running drop gives s_1..s_k (the paper's objective).
  bool segments = false;
  // Coefficients searched on a grid (name -> step, from the lower bound): the mesh
  // parameters, so that a search visits a few cached meshes rather than a new mesh per
  // evaluation. Discrete coefficients are on a grid of 1 already.
  std::map<std::string, double> grid;
  // Safety: a point that would become the best is first checked with this
  // (e.g. short drops from 0.3 and 2 m); a non-empty answer (why it is unsafe) rejects it as
  // a failed evaluation, so the search goes on elsewhere and never answers with it. Each
  // check costs safety_simulations runs, counted against the budget.
  std::function<std::string(const CoefficientValues&)> safety;
  int safety_simulations = 0;
  // Timing: the recorded flight times, impact to impact, of arcs 1..k (NaN:
  // not seen), against the simulated ones: the objective adds (w (f_i - g_i))^2, w in m/s (at
  // 1 m/s a flight 2 ms off weighs as a height 2 mm off); a flight f weighs at most as the
  // flight-time height g f^2 / 8 it gives (g f / 4 m/s: a 0.1 s hop's flight 0.25 m/s).
  // 0 or none: heights only.
  std::vector<double> recorded_flight_s;
  double flight_weight_mps = 0;
  // The first fall: from the drop height at rest to the first impact, seconds on the
  // heights' clock, and its standard uncertainty (NaN: not timed). Where the heights cannot
  // tell the air's drag, this duration can (fit/restitution_fit.h).
  double start_fall_s = std::nan("");
  double start_fall_sigma_s = 0;
  // Further drops of the same ball fitted with this one: each from its own
  // release height, its recorded heights (and flights) appended after this drop's in
  // recorded_m (recorded_flight_s); the objective sums over every drop.
  struct OtherDrop {
    double drop_height_m = 0;
    int bounces = 0;
  };
  std::vector<OtherDrop> other_drops;
  // Where drop d's bounces start in recorded_m (d = 0: this drop), and its release height.
  size_t DropStart(size_t d) const;
  double DropHeight(size_t d) const;
  size_t Drops() const { return 1 + other_drops.size(); }
};

struct SearchOptions {
  int max_evaluations = 200;       // simulations, at most
  std::atomic<int>* simulations = nullptr;  // counts every simulation run (progress)
  int threads = 0;                 // parallel simulations; 0 = all cores
  const CancelToken* cancel = nullptr;
  double target_rms_m = 0;         // stop once the RMS residual is at or below this
};

struct Evaluation {
  bool ok = false;           // the simulation ran (not diverged, not skipped)
  bool skipped = false;      // not run: cancelled or out of budget
  double objective = 0;      // sum (r_i - s_i)^2, or the failure penalty
  std::vector<double> simulated_m;  // s_1..s_k (0 where the ball made fewer bounces)
  std::vector<double> simulated_flight_s;  // flights of arcs 1..k (0 where not made)
  std::string failure;
};

struct SearchResult {
  std::string method;                 // "paper", "nlopt-bobyqa", ...
  CoefficientValues values;           // best point: free and fixed coefficients
  std::vector<double> simulated_m;
  double objective = 0;
  std::string failure;                // "" or why the best point is a failed run (none ran)
  double rms_m = 0;
  int evaluations = 0;                // simulations run (safety checks included)
  int safety_checks = 0;              // candidate best points checked for safety
  int rejected_unsafe = 0;            // of them, rejected as unsafe
  double wall_time_s = 0;
  bool cancelled = false;
  // Best-so-far objective after each simulation, in the order they finished.
  std::vector<double> best_history;
  // Heights Jacobian d s_i / d x_j in normalised units, at `jacobian_at`, if the search
  // computed one (rows: bounces, columns: free coefficients); empty otherwise.
  std::vector<std::vector<double>> jacobian;
  CoefficientValues jacobian_at;
  std::vector<std::string> inactive;  // free coefficients the search found to have no effect
};

class FitObjective {
 public:
  FitObjective(FitProblem problem, SearchOptions options);

  const FitProblem& problem() const { return problem_; }
  int dimension() const { return static_cast<int>(problem_.free.size()); }
  int threads() const { return threads_; }

  // Normalised x (clamped to [0, 1]) <-> coefficient values; discrete ones are rounded.
  CoefficientValues ToValues(const std::vector<double>& x) const;
  std::vector<double> ToUnit(const CoefficientValues& values) const;
  // Rounds discrete and gridded coordinates of x to their representable values (in place).
  void Snap(std::vector<double>* x) const;
  // One grid level of coordinate j in normalised units (0: continuous).
  double Level(size_t j) const;

  // One simulation (or a cache hit). Skipped, with the penalty, once stopped().
  Evaluation Evaluate(const std::vector<double>& x);
  // Several at once on the thread pool; results in input order.
  std::vector<Evaluation> EvaluateBatch(const std::vector<std::vector<double>>& xs);

  bool stopped() const;  // cancelled, budget used, or target reached
  bool cancelled() const;
  int evaluations() const { return evaluations_.load(); }
  int safety_checks() const { return safety_checks_.load(); }
  int rejected_unsafe() const { return rejected_unsafe_.load(); }
  double penalty() const { return penalty_; }

  std::vector<double> best_x() const;
  Evaluation best() const;
  std::vector<double> best_history() const;

  // Heights residuals r_i - s_i, then the weighted flight residuals w (f_i - g_i) of the
  // flights recorded (when timing is weighted): what a least-squares search drives to 0.
  std::vector<double> Residuals(const Evaluation& e) const;

  // Fills the common fields of a result from the best point.
  SearchResult MakeResult(const std::string& method, double wall_time_s) const;

 private:
  Evaluation Run(const std::vector<double>& x);
  // The simulated heights at these values: one drop, or one segment per bounce; the flights
  // of arcs 1..k into *flights.
  SimulationResult Simulate(const CoefficientValues& values, bool parallel,
                            std::vector<double>* flights) const;
  bool timed() const;
  bool Lookup(const std::vector<double>& x, Evaluation* out) const;
  bool BeatsBest(double objective) const;
  // problem_.safety on a candidate best point; an unsafe one becomes a failed evaluation.
  void CheckSafety(const std::vector<double>& x, Evaluation* e);
  void Record(const std::vector<double>& x, const Evaluation& e);

  FitProblem problem_;
  SearchOptions options_;
  int threads_ = 1;
  double penalty_ = 1;
  std::atomic<int> evaluations_{0};
  std::atomic<int> reserved_{0};  // budget slots taken by simulations started
  std::atomic<int> safety_checks_{0};
  std::atomic<int> rejected_unsafe_{0};
  mutable std::mutex mutex_;
  std::vector<std::pair<std::vector<double>, Evaluation>> cache_;
  std::vector<double> best_x_;
  Evaluation best_;
  bool have_best_ = false;
  std::vector<double> history_;
};

// model.Simulate, with an exception turned into a failed run (ok = false, its message).
SimulationResult SimulateSafely(const BallModel& model, const CoefficientValues& values,
                                const SimulationOptions& options);

// sum (r_i - s_i)^2 with s_i = 0 for bounces the simulation did not make.
double HeightObjective(const std::vector<double>& recorded, const std::vector<double>& simulated);
double RmsResidual(const std::vector<double>& recorded, const std::vector<double>& simulated);
// Flight times of arcs 1..k from impact times (impact 0 ends the release fall); 0 where the
// simulation made fewer impacts.
std::vector<double> FlightTimes(const std::vector<double>& impact_times_s, size_t k);

// Release-to-apex time of bounce k for a drag-free ball with these apex heights (h_0 the
// drop height): how long a simulation must run to see bounce k.
double FreeFallApexTime(double drop_height_m, const std::vector<double>& heights_m, int k);

// Ranks a coefficient name in the paper's priority order (linear, angular, volume stiffness,
// pressure, damping, drag, lift, the three impulse splits, mesh resolution, radius/edge,
// volume constraint); unknown names rank after all of them.
int PaperPriority(const std::string& name);

}  // namespace bouncefit
