#include "cli/commands.h"

namespace bouncefit::cli {

void AddReplayLogCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("replay-log", "Republish an LCM log so detect and fit can be rerun without video");
  cmd->callback([] { NotYetAvailable("replay-log", 4); });
}

}  // namespace bouncefit::cli
