#pragma once
// Uncertainty and identifiability of fitted coefficients from the local sensitivity of the
// bounce heights: J = d s_i / d c_j at the fit, covariance sigma^2 (J^T J)^-1 with sigma
// the larger of the measurement uncertainty and the fit's residual scatter. A coefficient
// that moves no height (zero column), or that lies in a direction the data cannot pin
// down (near-null space of J, e.g. more coefficients than bounces), is not identifiable:
// its sigma is NaN and it is named.
#include <string>
#include <vector>

#include "fit/fit_objective.h"

namespace bouncefit {

struct CoefficientEstimate {
  std::string name;
  std::string unit;
  double value = 0;
  double sigma = 0;            // standard uncertainty, in the coefficient's unit; NaN if not identifiable
  bool identifiable = false;
  double height_effect_m = 0;  // max |change of a height| across the coefficient's full range (linearised)
  std::string note;            // "no effect on the heights", "degenerate with others", ...
  // "lower" / "upper": the fit put it at that bound, and sigma is one-sided, into the range.
  std::string bound;
};

struct SensitivityOptions {
  double min_effect_m = 1e-5;     // full-range effect below this: no effect
  double null_tolerance = 1e-3;   // relative singular value below which a direction is unresolved
  double null_loading = 0.3;      // a coefficient loading more than this on such a direction
  double max_sigma_fraction = 0.5;  // sigma above this fraction of the range: not identifiable
};

// `jacobian_unit`: k rows (bounces) x free.size() columns, in metres per unit of the
// normalised coefficient (its range maps to [0, 1]).
std::vector<CoefficientEstimate> EstimateUncertainty(
    const std::vector<CoefficientSpec>& free, const CoefficientValues& values,
    const std::vector<std::vector<double>>& jacobian_unit, double residual_rms_m,
    double measurement_sigma_m, const SensitivityOptions& options = {});

// Central-difference Jacobian at `values` (normalised step `step`), simulations in
// parallel through the objective (counted in its evaluations).
std::vector<std::vector<double>> HeightsJacobian(FitObjective& objective,
                                                 const CoefficientValues& values,
                                                 double step = 0.02);

}  // namespace bouncefit
