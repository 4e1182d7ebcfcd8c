#include "cli/commands.h"

namespace bouncefit::cli {

void AddReportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("report", "Write report.html and figures from a run's output directory");
  cmd->callback([] { NotYetAvailable("report", 8); });
}

}  // namespace bouncefit::cli
