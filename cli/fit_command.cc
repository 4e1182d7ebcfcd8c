#include "cli/commands.h"

namespace bouncefit::cli {

void AddFitCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("fit", "Fit a soft-body ball model after every bounce; publish FIT_UPDATE");
  cmd->callback([] { NotYetAvailable("fit", 7); });
}

}  // namespace bouncefit::cli
