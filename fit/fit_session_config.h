#pragma once
// The fit session's settings (fit/fit_session.h), and what they decide on their own: whether
// they are known values, which coefficients are searched and in what order.
#include <map>
#include <string>
#include <vector>

#include "model/ball_model.h"

namespace bouncefit {

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

// Throws std::invalid_argument for a method, objective, impact or live method it does not
// know, or a free coefficient `model` does not have.
void ValidateFitSessionConfig(const FitSessionConfig& config, const BallModel& model);

// The coefficients the session searches: config.free, else every one with bounds but the
// never-fitted ones; in the paper's priority order.
std::vector<CoefficientSpec> FreeCoefficients(const BallModel& model, const FitSessionConfig& config);

// The free coefficients' names, config.live_priority's first, then the others in order.
std::vector<std::string> LiveOrder(const std::vector<CoefficientSpec>& free, const FitSessionConfig& config);

// The first n of `free` in `order` (names).
std::vector<CoefficientSpec> FirstCoefficients(const std::vector<CoefficientSpec>& free,
                                               const std::vector<std::string>& order, int n);

// The final fit is the restitution law's two stages: config impact "restitution", the model
// has the law, a quick model to start it.
bool UsesRestitutionLaw(const FitSessionConfig& config, const BallModel& model, const BallModel* quick_model);

}  // namespace bouncefit
