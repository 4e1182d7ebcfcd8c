#pragma once
// What the fit takes in and gives out: a recorded apex (PeakInput) and one fit's answer
// (FitUpdate), per bounce or final.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

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

}  // namespace bouncefit
