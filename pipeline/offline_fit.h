#pragma once
// The fit of recorded drops without a stream, as the fit stage would make it: `fit --heights
// / --peaks` and the joint fit of several clips' drops (`run a.mp4 b.mp4`): the point-mass
// estimate and a refinement after every bounce, then the final fit of the last drop jointly
// with the earlier ones.
#include <filesystem>
#include <functional>
#include <vector>

#include "fit/fit_session.h"
#include "fit/fit_timeline.h"
#include "fit/fit_models.h"

namespace bouncefit {

// The drops of a peaks.csv (msgs/peaks_csv.h) as the fit's peaks: the height to quote of
// every row, its bounce and time. A drop starts at its first row, whatever its bounce (the
// release when seen, else the first apex in view: any apex is a start); a row of another
// `drop` than the one before, or whose bounce does not follow it (bounce 0 again, or a number
// not above it), starts the next drop. drop_numbers (may be null): each drop's `drop` there.
// Throws std::runtime_error with a one-line reason (no file, no rows, not a number).
std::vector<std::vector<PeakInput>> ReadPeaksDrops(const std::filesystem::path& peaks_csv,
                                                   std::vector<int>* drop_numbers = nullptr);
// The first of them.
std::vector<PeakInput> ReadDropPeaks(const std::filesystem::path& peaks_csv);

// Fits the drops (each a list of peaks from its start: bounce 0 when the release was seen,
// else its first apex); emit gets every update, the final one last; progress (simulations
// run, budget) about once a second during the final fit. Returns the final update (its
// no_answer set when it is no answer). Throws std::runtime_error when no drop has an apex
// after its start high enough to fit. fitted (may be null): for the final update's drops in
// its order (the last drop, then the earlier ones it kept), each one's index in `drops` and
// the bounce its fit started from.
FitUpdate FitDropsOffline(std::vector<std::vector<PeakInput>> drops, const FitSetup& setup, bool final_only,
                          const std::function<void(const FitUpdate&)>& emit,
                          const std::function<void(int, int)>& progress = {},
                          std::vector<std::pair<size_t, int>>* fitted = nullptr);

// The final fit's drops on their peak files' timeline (fit/fit_timeline.h), from what
// FitDropsOffline said it fitted: each drop numbered by its index in `drops`, its bounces and
// times those of its peaks.
std::vector<FitDrop> OfflineFitDrops(const FitUpdate& fit, const std::vector<std::vector<PeakInput>>& drops,
                                     const std::vector<std::pair<size_t, int>>& fitted);

}  // namespace bouncefit
