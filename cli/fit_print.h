#pragma once
// A fit update printed for a person: residual, coefficients with their uncertainty, heights,
// drops (`fit` and `run a.mp4 b.mp4`).
#include "pipeline/offline_fit.h"

namespace bouncefit::cli {

void PrintFitUpdate(const FitUpdate& u);

}  // namespace bouncefit::cli
