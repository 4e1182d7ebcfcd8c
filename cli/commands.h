#pragma once
// Each subcommand lives in its own <name>_command.cc and registers itself on the app.
// A command reports failure by throwing: std::exception -> "bouncefit <cmd>: error: ...",
// exit 1; CLI::RuntimeError(code) -> exit code as given, no message.
#include <CLI/CLI.hpp>

#include <string>

namespace bouncefit::cli {

void AddCaptureCommand(CLI::App& app);
void AddDetectCommand(CLI::App& app);
void AddFitCommand(CLI::App& app);
void AddRunCommand(CLI::App& app);
void AddWatchCommand(CLI::App& app);
void AddReportCommand(CLI::App& app);
void AddSynthCommand(CLI::App& app);
void AddSimulateCommand(CLI::App& app);
void AddPredictCommand(CLI::App& app);
void AddReplayLogCommand(CLI::App& app);

}  // namespace bouncefit::cli
