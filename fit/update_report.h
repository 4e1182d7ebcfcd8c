#pragma once
// A search's answer as a FitUpdate: the drop it was about, the heights, and every coefficient
// the session may fit with its uncertainty and covariance from the heights Jacobian.
#include <cmath>
#include <cstdint>
#include <vector>

#include "fit/fit_objective.h"
#include "fit/fit_update.h"
#include "model/ball_model.h"

namespace bouncefit {

// What the session knows of the update beyond the search: the drop and the coefficients it
// reports.
struct UpdateContext {
  int64_t utime = 0;
  int sequence = 0;
  int start_bounce = 0;
  int after_bounce = 0;           // this drop's last bounce fitted
  double drop_height_m = 0;
  double flight_clock_ratio = std::nan("");  // the drop's flights dropped for another clock (NaN: none)
  double measurement_sigma_m = 0;
  // Every coefficient reported: those not searched keep their value, without an uncertainty.
  std::vector<CoefficientSpec> reported;
  // Where the coefficients hold when their values do not say (0: unknown).
  double time_step_s = 0;
  int iterations = 0;
};

// `jacobian` (rows: bounces, columns: problem.free; empty: none) gives the uncertainties;
// extra_evals are simulations run besides the search's.
FitUpdate ReportUpdate(const UpdateContext& context, const FitProblem& problem, const SearchResult& r,
                       bool final, const std::vector<std::vector<double>>& jacobian, int extra_evals,
                       double wall_s, const BallModel& model);

// Where the coefficients of a model hold: time step and solver iterations, read from
// coefficient values whose names contain "time_step" / "iterations" (0 when absent).
double TimeStepOf(const CoefficientValues& values);
int IterationsOf(const CoefficientValues& values);

}  // namespace bouncefit
