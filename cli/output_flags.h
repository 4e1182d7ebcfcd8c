#pragma once
// The output folder on every node that writes one: --out and --overwrite, one help text each.
// Its files are claimed where they are written (pipeline/output_dir.h).
#include <CLI/CLI.hpp>

#include <string>

namespace bouncefit::cli {

// `files`: what the command writes there, for the help ("peaks.csv, impacts.csv").
// Returns --out, for a command that shows its default.
CLI::Option* AddOutputFlags(CLI::App* cmd, std::string* out, bool* overwrite, const std::string& files);

}  // namespace bouncefit::cli
