#include "cli/commands.h"

namespace bouncefit::cli {

void AddSimulateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Simulate the soft-body ball model for given coefficients");
  cmd->callback([] { NotYetAvailable("simulate", 6); });
}

}  // namespace bouncefit::cli
