#include "cli/commands.h"

namespace bouncefit::cli {

void AddRunCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "Everything in one process: replay a clip (or the built-in sample), track, detect, fit");
  cmd->callback([] { NotYetAvailable("run", 8); });
}

}  // namespace bouncefit::cli
