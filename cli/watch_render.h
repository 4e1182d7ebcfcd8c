#pragma once
// The dashboard of `bouncefit watch` as lines of text: no escapes, so the same lines serve
// the full-screen view, `--once` and the tests.
#include <cstdint>
#include <string>
#include <vector>

#include "cli/watch_state.h"

namespace bouncefit::cli {

struct WatchRenderOptions {
  int cols = 100;
  int rows = 40;
  bool unicode = true;     // block characters for the trace; ASCII ramps otherwise
  int chart_rows = 8;      // height of the trace chart
  bool show_keys = true;   // the "q: quit" line
  std::string source;      // "udpm://..." shown in the title line
  int64_t decode_failures = 0;   // from the bus
  int64_t handler_failures = 0;
  std::vector<std::string> channel_names = {"BALL_BOX", "CALIBRATION", "BOUNCE_PEAK",
                                            "FIT_UPDATE", "IMPACT"};
};

std::vector<std::string> RenderWatch(const WatchState& state, int64_t now_utime,
                                     const WatchRenderOptions& options);

// A one-line sparkline of the last `width` buckets of the height trace.
std::string Sparkline(const WatchState& state, int width, bool unicode);

// Plain mode's line for each event (after the state has taken the message in). Times are
// seconds since the first box this watcher saw of the stream.
std::string WatchCalibrationLine(const calibration_t& m);
std::string WatchPeakLine(const WatchState& state, const bounce_peak_t& m);
std::string WatchFitLine(const fit_update_t& m);
std::string WatchImpactLine(const WatchState& state, const impact_t& m);

// The status line for plain mode: rates, drops, waiting.
std::string WatchStatusLine(const WatchState& state, int64_t now_utime,
                            const WatchRenderOptions& options);

}  // namespace bouncefit::cli
