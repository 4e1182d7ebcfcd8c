#pragma once
// The tracker's flags, shared by `capture` and `run`: colour choice, ROI and tunables.
#include <CLI/CLI.hpp>

#include <string>

#include "track/tracker.h"

namespace bouncefit::cli {

// Adds --pick, --color, --roi and the tracker tunables to `cmd`, writing into *config (which
// must outlive parsing). Values are checked when parsed; a bad one is a one-line CLI error.
void AddTrackerFlags(CLI::App* cmd, TrackerConfig* config);

// "orange", a ball preset name ("pingpong") or "B,G,R" (0-255 each) to a BGR colour; throws
// std::invalid_argument with a one-line message otherwise.
void ParseTrackerColor(const std::string& text, double bgr[3]);

}  // namespace bouncefit::cli
