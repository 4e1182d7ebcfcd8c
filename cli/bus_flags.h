#pragma once
// The same bus flags on every node: --lcm-url and one override per channel.
#include <CLI/CLI.hpp>

#include <string>

#include "msgs/channels.h"

namespace bouncefit::cli {

void AddBusFlags(CLI::App* cmd, std::string* lcm_url, Channels* channels);
// --lcm-url alone, for a command that takes any channel.
void AddLcmUrlFlag(CLI::App* cmd, std::string* lcm_url);

}  // namespace bouncefit::cli
