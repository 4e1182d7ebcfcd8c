#include "cli/commands.h"

namespace bouncefit::cli {

void AddSynthCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "Render a ball-drop clip with known ground truth");
  cmd->callback([] { NotYetAvailable("synth", 2); });
}

}  // namespace bouncefit::cli
