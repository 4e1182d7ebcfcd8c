#include "cli/commands.h"

namespace bouncefit::cli {

void AddCaptureCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("capture", "Read a camera (V4L2) or replay a clip as a fake camera; track the ball and publish BALL_BOX");
  cmd->callback([] { NotYetAvailable("capture", 4); });
}

}  // namespace bouncefit::cli
