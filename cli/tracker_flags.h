#pragma once
// The tracker's flags, shared by `capture` and `run`: colour choice, ROI and tunables.
#include <CLI/CLI.hpp>

#include <string>

#include "track/tracker.h"

namespace bouncefit::cli {

// Adds --pick, --color, --pick-window, --roi and the tracker tunables to `cmd`, writing into
// *config and *pick_window (which must outlive parsing). Values are checked when parsed; a bad
// one is a one-line CLI error. The window itself is cli/pick_window.h.
void AddTrackerFlags(CLI::App* cmd, TrackerConfig* config, bool* pick_window);

// "orange", a ball preset name ("pingpong") or "B,G,R" (0-255 each) to a BGR colour; throws
// std::invalid_argument with a one-line message otherwise.
void ParseTrackerColor(const std::string& text, double bgr[3]);

}  // namespace bouncefit::cli
