#include "cli/commands.h"

namespace bouncefit::cli {

void AddWatchCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("watch", "Live terminal dashboard of a running session over LCM");
  cmd->callback([] { NotYetAvailable("watch", 8); });
}

}  // namespace bouncefit::cli
