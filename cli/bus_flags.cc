#include "cli/bus_flags.h"

namespace bouncefit::cli {

void AddLcmUrlFlag(CLI::App* cmd, std::string* lcm_url) {
  cmd->add_option("--lcm-url", *lcm_url, "LCM URL (memq:// keeps it in this process)")
      ->capture_default_str();
}

void AddBusFlags(CLI::App* cmd, std::string* lcm_url, Channels* channels) {
  AddLcmUrlFlag(cmd, lcm_url);
  cmd->add_option("--ball-box-channel", channels->ball_box, "channel of ball boxes")
      ->capture_default_str();
  cmd->add_option("--calibration-channel", channels->calibration, "channel of calibrations")
      ->capture_default_str();
  cmd->add_option("--bounce-peak-channel", channels->bounce_peak, "channel of bounce peaks")
      ->capture_default_str();
  cmd->add_option("--fit-update-channel", channels->fit_update, "channel of fit updates")
      ->capture_default_str();
  cmd->add_option("--impact-channel", channels->impact, "channel of impacts (heard, seen)")
      ->capture_default_str();
  cmd->add_option("--stream-channel", channels->stream, "channel of the capture's stream start and end")
      ->capture_default_str();
  cmd->add_option("--drop-channel", channels->drop, "channel of drops ended and streams done")
      ->capture_default_str();
}

}  // namespace bouncefit::cli
