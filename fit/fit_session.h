#pragma once
// A fit that follows a drop bounce by bounce.
//
// Any apex seen or heard is a state the simulation can start from: the ball at that height,
// at rest vertically. The start is bounce 0 (the release) when it was seen, else the first
// apex in view (a throw, a release not in view, a clip begun mid-bounce, heard-only impacts);
// the apexes after it are r_1..r_k. After each, Update() refines
// the coefficients so that the simulated s_1..s_k match the recorded r_1..r_k (objective
// sum (r_i - s_i)^2 inside the coefficients' bounds), warm-started from the previous
// answer. QuickUpdate() is the point-mass estimate (restitution, its speed dependence and
// drag), milliseconds. FinalUpdate() is the thorough fit at the end of a drop: every free
// coefficient, a larger budget, and uncertainties from the heights Jacobian at the answer;
// it starts where the drop's fits started (not from the per-bounce updates), so the same
// peaks give the same final fit.
// Updates take a cancellation token checked between simulations: a cancelled update
// returns with `cancelled` set and its best point kept as the next warm start.
//
// Synchronous and single-threaded from the caller's view (simulations inside run on a
// thread pool); FitWorker runs it on a thread with supersede semantics.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fit/fit_objective.h"
#include "fit/restitution_fit.h"
#include "fit/restitution_points.h"
#include "fit/sensitivity.h"
#include "model/ball_model.h"

namespace bouncefit {

struct PeakInput {
  int sequence = 0;
  int bounce = 0;             // 0: release height; 1, 2, ...: rebound apexes
  double height_m = 0;        // ball bottom above the floor, metres
  double sigma_m = 0;         // standard uncertainty of the height (0: unknown)
  int64_t utime = 0;          // capture time that triggered it (copied to the update)
  // When the impact that starts this arc happened, seconds on any clock the drop shares
  // (NaN: unknown); consecutive ones give the flight times the fit's timing uses.
  double impact_before_s = std::nan("");
  // When the ball was at this apex, on the impacts' clock (NaN: unknown): with the impact
  // after it, the fall from the start apex that times the air's drag.
  double apex_s = std::nan("");
};

struct FitUpdate {
  int64_t utime = 0;
  int sequence = 0;
  int after_bounce = 0;       // uses bounces start_bounce+1..after_bounce
  int start_bounce = 0;       // the apex the simulation starts from (0: the release)
  bool final = false;
  bool cancelled = false;     // superseded before it finished (best point so far)
  std::string model;          // "point-mass", "bullet-softbody", ...
  std::string method;         // "least-squares", "nlopt-bobyqa", "paper"
  std::vector<CoefficientEstimate> coefficients;  // the fitted ones, with uncertainty
  CoefficientValues values;   // every coefficient the model was run with
  double drop_height_m = 0;
  std::vector<double> recorded_m;   // r_1..r_k (bounces above the minimum height)
  std::vector<double> simulated_m;  // s_1..s_k (final: one free-running drop, as `simulate`)
  double residual_m = 0;      // RMS of s_i - r_i
  // Multiple shooting (FitSessionConfig::objective "segments"): what was fitted, bounce i
  // simulated from the recorded apex i-1, and its RMS residual.
  std::vector<double> segment_simulated_m;
  double segment_residual_m = std::nan("");
  // The final fit's check, the free-running drop as an ensemble (fit/drop_ensemble.h): mean
  // and spread per bounce, and the RMS residual of the mean.
  std::vector<double> free_run_mean_m;
  std::vector<double> free_run_sd_m;
  double free_run_residual_m = std::nan("");
  int evaluations = 0;        // simulations run
  int safety_checks = 0;      // final fit: candidate answers dropped from the safe heights
  int rejected_unsafe = 0;    // of them, rejected because they diverged
  double wall_time_s = 0;
  double time_step_s = 0;     // simulation step the coefficients hold for (0: n/a)
  int iterations = 0;         // solver iterations they hold for (0: n/a)
  std::vector<std::string> no_effect;      // coefficients found to change no height
  std::vector<std::string> unidentified;   // coefficients the data cannot determine
  // Covariance of the identifiable fitted coefficients (their units), from the Jacobian.
  std::vector<std::string> covariance_names;
  std::vector<std::vector<double>> covariance;
  std::string warning;        // "" or why the answer is doubtful (e.g. its free drop diverges)
  // Final fit: "" for an answer; else why it is none (its residual is more than the heights'
  // measurement explains): a caller reports "no fit: <why>" and writes no coefficients.
  std::string no_answer;
  // The law's coefficients the final fit did not search, one line each with what holds them:
  // at a bound where the bounces put it, or (not identifiable) the preset's or the data's value.
  std::vector<std::string> held;
  // A joint fit of several drops: recorded_m / simulated_m / free_run_* hold this drop's
  // bounces, then each other drop's; their release heights and bounce counts (empty: one).
  std::vector<double> other_drop_heights_m;
  std::vector<int> other_drop_bounces;
  // Final fit: the recorded bounces' restitution impact by impact, every drop (the earlier
  // ones first, this drop last), and what they say together: the impacts' scatter, each
  // drop's e at one speed, the bounces to doubt (fit/restitution_points.h).
  std::vector<RestitutionPoint> restitution_points;
  RestitutionConsistency restitution;
};

struct FitSessionConfig {
  std::string method = "nlopt";     // "nlopt" (default) or "paper"
  // "segments": multiple shooting, every bounce its own segment from the recorded apex before
  // it (FitProblem::segments); "drop" (default): one free-running drop (the paper's). Not yet
  // the default: its free-running residual and transfer are not measured to beat "drop"
  // (docs/ACCURACY.md).
  std::string objective = "drop";
  // The impact (docs/MODEL.md): "restitution" (default: the rebound law e(v) = e0 - k v; the
  // final fit is fit/restitution_fit.h's two stages, ~60 simulations; it transfers to other
  // drop heights, docs/ACCURACY.md) or "boost" (the paper's extra force on Bullet's own
  // rebound; the final fit searches every coefficient, ~940 simulations).
  std::string impact = "restitution";
  // Timing: flight times (impact to impact) in the objective with this weight, m/s (0: off).
  // With the restitution law only: the boost's soft contact puts every impact ~15 ms late.
  double flight_weight_mps = 1.0;
  // The standard uncertainty of an interval between an apex and an impact, seconds on the
  // stream's clock: each timed to about a quarter of a 30 fps frame.
  double time_sigma_s = 0.008;
  int ensemble_members = 8;         // the final fit's free-running check (0: none)
  // A stream's later drops (the person drops the ball again) are fitted jointly with the
  // earlier ones in the final fits; false: each drop on its own.
  bool joint_drops = true;
  // Safety (the user may drop it anywhere in 0.3-2 m): inside the final
  // fit's search, a point that would become the best is first dropped from these heights
  // and from the fitted one, each until it settles, and rejected if one diverges (empty: no
  // check). The answer is dropped from them again after the fit (a warning if it diverges).
  std::vector<double> safe_drops_m = {0.3, 2.0};
  // The check inside the search: for models that can diverge (ConfigureSessionForModel turns
  // it on for the soft ball); a smooth model would only spend budget on it.
  bool safe_search = false;
  // The safe drops end at hops lower than this (ConfigureSessionForModel: a tenth of the
  // ball's diameter, at least 1 cm; a basketball's 1 cm hops are contact chatter).
  double safe_min_bounce_m = 0.01;
  int max_evaluations_per_bounce = 16;  // per-bounce update budget (simulations)
  // Final fit budget, everything included: 900 for the searches (chaotic heights:
  // docs/MODEL.md), the Jacobian (2 x 16 + 2) and the free-running checks (8 + 1 + 2).
  int max_evaluations_final = 945;
  int final_starts = 3;                 // the final fit's starts (budget shared), best kept
  int max_evaluations_quick = 120;      // point-mass estimate budget
  // Per-bounce update: "gauss-newton" (default: one parallel Gauss-Newton step, two rounds of
  // simulations, so it is out before the next apex) or "search" (`method` with the
  // per-bounce budget).
  std::string live_method = "gauss-newton";
  int live_coefficients = 1;        // per-bounce: at most this many (and <= bounces)
  double live_duration_margin = 1.1;  // per-bounce simulations stop sooner (+0.08 s)
  // Per-bounce updates search these first (the model's most influential coefficients);
  // empty: the paper's priority order. A final fit reorders by measured sensitivity.
  std::vector<std::string> live_priority;
  int threads = 0;                  // parallel simulations; 0 = all cores
  double min_bounce_height_m = 0.01;  // bounces lower than this are not fitted
  double default_sigma_m = 0.002;   // height uncertainty when a peak gives none
  double duration_margin = 1.5;     // simulate this x the free-fall time to bounce k (+0.2 s)
  // A final fit is an answer only when its RMS residual is at most the larger of these: the
  // floor and the fraction of the highest recorded apex (else FitUpdate::no_answer). Heights
  // measured badly give no answer rather than a loose one.
  double answer_floor_m = 0.003;
  double answer_fraction = 0.05;
  // The ball's air: rho A / 2m, per metre per unit of drag coefficient (ConfigureSessionForModel;
  // 0: the restitution points are measured without drag).
  double air_per_m_per_cd = 0;
  double target_rms_fraction = 0;   // stop early at RMS <= this x drop height (0: never)
  // Coefficients searched (empty: every model coefficient with bounds, minus the
  // never-fitted ones below). The model's other coefficients stay at `start`/defaults.
  std::vector<std::string> free;
  // Never fitted: mass, radius/diameter, time step, iterations, ... (substring match).
  std::vector<std::string> never_fit = {"mass", "radius_m", "diameter", "time_step",
                                        "iterations", "substeps", "floor_", "gravity"};
  CoefficientValues start;          // warm start of the first fit (e.g. a preset table)
  // Mesh parameters searched on a grid of cached meshes (name -> step).
  std::map<std::string, double> grid = {{"radius_edge_ratio", 0.2}, {"max_volume", 0.01}};
  // What the coefficients hold for, reported with every update (from the model's config).
  double time_step_s = 0;
  int iterations = 0;
  bool quick_fit = true;            // QuickUpdate() available (needs a quick model)
};

class FitSession {
 public:
  // `model` is fitted; `quick_model` (may be null) gives QuickUpdate(). Both must outlive
  // the session.
  FitSession(const BallModel& model, const BallModel* quick_model, FitSessionConfig config);

  // Starts a new drop (forgets heights; keeps the warm start).
  void Reset(int sequence);
  // Keeps the drop recorded so far (when it has a bounce to fit) for the final fits that
  // follow, fitted jointly with the next drops, then starts a new drop.
  void KeepDropAndReset(int sequence);
  int kept_drops() const { return static_cast<int>(kept_.size()); }
  // Records a peak (a later one of the same bounce replaces it: a revision). The start is
  // bounce 0 when seen, else the first apex of the longest unbroken run of apexes at least
  // min_bounce_height_m high; the apexes after it are r_1, r_2, ... Returns false (and
  // records nothing) for a peak of another sequence: call Reset() first.
  bool AddPeak(const PeakInput& peak);

  int sequence() const { return sequence_; }
  bool has_drop_height() const { return drop_height_m_ > 0; }
  double drop_height_m() const { return drop_height_m_; }  // the start's height
  int start_bounce() const { return start_bounce_; }
  int bounces() const { return start_bounce_ + static_cast<int>(heights_.size()); }  // last bounce index seen
  std::vector<double> FittedHeights() const;  // r_1.. above the minimum height
  // Flight times of the fitted arcs (impact before arc i+1 minus impact before arc i; NaN
  // where either is unknown; all NaN when their median is more than 20% off the flights the
  // heights give: impacts timed on another clock than the heights were measured with).
  std::vector<double> FittedFlights() const;
  bool CanFit() const { return has_drop_height() && !FittedHeights().empty(); }

  FitUpdate QuickUpdate();
  FitUpdate Update(const CancelToken* cancel = nullptr);
  FitUpdate FinalUpdate(const CancelToken* cancel = nullptr);
  // Simulations FinalUpdate() runs at most, everything included (what its progress reads
  // against: never past it).
  int FinalBudget() const;

  const CoefficientValues& warm_start() const { return current_; }
  const FitSessionConfig& config() const { return config_; }
  const BallModel& model() const { return model_; }
  // Simulations run by all fits so far (read from any thread: progress of a running fit).
  int simulations() const { return simulations_.load(); }

 private:
  std::vector<CoefficientSpec> FreeSpecs() const;
  // The final fit is the restitution law's two stages (config impact "restitution", the
  // model has the law, a quick model to start it).
  bool UsesRestitutionLaw() const;
  // Simulations after the search: the Jacobian and the free-running checks.
  int AfterSearchSimulations() const;
  FitProblem MakeProblem(const std::vector<CoefficientSpec>& free, const CoefficientValues& at,
                         bool live = false) const;
  double MeasurementSigma() const;
  // The first n free coefficients in `order` (names of free coefficients).
  std::vector<CoefficientSpec> FirstSpecs(const std::vector<std::string>& order, int n) const;
  // One start of the final fit: Gauss-Newton rounds on the lead_n most influential
  // coefficients from final_start_, then the thorough search, within `budget` simulations.
  SearchResult FinalSearch(int lead_n, int budget, const SearchOptions& options) const;
  // The final fit's problems reject candidate answers that diverge from config_.safe_drops_m.
  FitProblem WithSafety(FitProblem p) const;
  // The restitution impact's final fit: the law's curve in two stages; *p its problem.
  // *held: the law's coefficients stage 1 held, and at what.
  SearchResult FinalRestitutionSearch(int budget, const SearchOptions& options, FitProblem* p,
                                      std::vector<HeldCoefficient>* held) const;
  // The final fit's free-running check: simulated_m and residual_m from one drop as
  // `simulate` runs it, free_run_* from the ensemble.
  void CheckFreeRun(const FitProblem& problem, FitUpdate* update);
  FitUpdate Finish(const FitProblem& problem, const SearchResult& r, bool final,
                   const std::vector<std::vector<double>>& jacobian, int extra_evals,
                   double wall_s, const BallModel& model);

  const BallModel& model_;
  const BallModel* quick_model_;
  FitSessionConfig config_;
  // Every apex of the drop by bounce index; the start and the vectors below follow from it.
  struct Apex {
    double height_m = 0, sigma_m = 0, impact_before_s = 0, apex_s = std::nan("");
  };
  std::map<int, Apex> apexes_;
  // FittedFlights(): the recorded flights over those the heights give, when they disagree
  // so much that they are not used (NaN: used, or none).
  mutable double flight_clock_ratio_ = std::nan("");
  // The start apex to the impact after it (seconds on the impacts' clock; NaN: unknown).
  double StartFall() const;
  void ChooseStart();
  int sequence_ = 0;
  int start_bounce_ = 0;
  double drop_height_m_ = 0;
  std::vector<double> heights_;   // index i: bounce start+i+1 (NaN until seen)
  std::vector<double> sigmas_;
  std::vector<double> impacts_before_;  // index i: the impact starting bounce i+1's arc
  int64_t last_utime_ = 0;
  CoefficientValues current_;     // warm start of the model
  CoefficientValues final_start_; // start of the next final fit: the table or the last final
  CoefficientValues quick_current_;
  bool quick_fitted_ = false;     // quick_current_ holds a QuickUpdate's answer
  std::vector<std::string> live_order_;  // free coefficients, most sensitive first
  std::vector<std::string> initial_live_order_;  // as configured: the final fit's lead
  std::atomic<int> simulations_{0};
  struct KeptDrop {
    double drop_height_m = 0;
    std::vector<double> heights_m, flights_s;
    std::vector<double> sigmas_m;  // the start's, then the heights'
    int start_bounce = 0;
  };
  // This drop as a joint fit keeps it (CanFit() must hold).
  KeptDrop ThisDrop() const;
  // Every drop's restitution points (kept drops first), the air's drag from `values`.
  std::vector<RestitutionPoint> RestitutionPoints(const CoefficientValues& values) const;
  std::vector<KeptDrop> kept_;  // earlier drops, fitted with this one in final fits
};

// A joint fit's answer holds for every drop: "" when each drop's fitted heights are within
// max(floor_m, fraction x its highest apex) RMS of its recorded ones, else which drop is not
// (numbered in time: the kept drops, then the fit's own).
std::string DropOutsideItsGate(const FitUpdate& u, double floor_m, double fraction);

// Where the coefficients of a model hold: time step and solver iterations, read from
// coefficient values whose names contain "time_step" / "iterations" (0 when absent).
double TimeStepOf(const CoefficientValues& values);
int IterationsOf(const CoefficientValues& values);

}  // namespace bouncefit
