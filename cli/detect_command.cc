#include "cli/commands.h"

namespace bouncefit::cli {

void AddDetectCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("detect", "Calibrate and detect bounce apexes from BALL_BOX; publish CALIBRATION and BOUNCE_PEAK");
  cmd->callback([] { NotYetAvailable("detect", 5); });
}

}  // namespace bouncefit::cli
