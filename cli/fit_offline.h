#pragma once
// The offline fit of recorded drops, shared by `fit --heights/--peaks` and `run a.avi b.avi`:
// the point-mass estimate and a refinement after every bounce, then the final fit of the last
// drop jointly with the earlier ones (issue 14 item 4).
#include <functional>
#include <string>
#include <vector>

#include "fit/fit_session.h"
#include "fit/node/fit_node.h"

namespace bouncefit::cli {

// peaks.csv (docs/FORMATS.md): columns by header name (the fused height where a run wrote
// one); rows of bounce 0 start a new drop, only the first drop is read. Throws
// std::runtime_error with a one-line reason (no file, no rows, no release, not a number).
std::vector<PeakInput> ReadPeaksCsv(const std::string& path);

// Fits the drops (each a list of peaks, bounce 0 first) as FitNode's session would; emit gets
// every update, the final one last (with progress, the final fit's on stderr). Returns the
// final update. Throws std::runtime_error when no bounce is high enough to fit.
FitUpdate FitDropsOffline(std::vector<std::vector<PeakInput>> drops, FitNodeConfig node,
                          bool final_only, const std::function<void(const FitUpdate&)>& emit,
                          bool progress = true);

// A fit update as text: residual, coefficients with their uncertainty, heights, drops.
void PrintFitUpdate(const FitUpdate& u);

}  // namespace bouncefit::cli
