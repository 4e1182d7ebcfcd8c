// bouncefit replay-log: republish an LCM log with its original pacing (scaled), so detect
// and fit can be rerun without video (pipeline/lcm_log_replay.h).
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <regex>
#include <stdexcept>

#include "cli/bus_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "cli/stop_signal.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"
#include "pipeline/lcm_log_replay.h"

namespace bouncefit::cli {
namespace {

struct ReplayLogOptions {
  std::string log;
  LogReplayConfig replay;
  std::string lcm_url = kDefaultLcmUrl;
  bool quiet = false;
};

void Run(const ReplayLogOptions& o) {
  // A missing or foreign file, or a bad regex: one error line, nothing else.
  { LcmLogReader check(o.log); }
  try {
    std::regex check(o.replay.channels_regex);
  } catch (const std::regex_error&) {
    throw std::invalid_argument("--channels is not a valid regular expression: '" +
                                o.replay.channels_regex + "'");
  }
  LcmBus bus(o.lcm_url);
  const std::atomic<bool>& stop = StopOnSignal();
  if (!o.quiet) {
    fmt::print("replay-log: {} -> {}, channels /{}/, {}\n", o.log, o.lcm_url, o.replay.channels_regex,
               o.replay.speed > 0 ? fmt::format("speed {:g}", o.replay.speed) : "as fast as possible");
    std::fflush(stdout);
  }
  LogReplayStats stats;
  std::string failure;
  try {
    ReplayLcmLog(o.log, o.replay, PublishOn(bus), &stats, &stop);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    failure = e.what();
  }
  if (stats.events > 0 || failure.empty())
    fmt::print("replay-log: {}{} of {} messages republished, log span {:.3f} s, wall {:.3f} s{}\n",
               stop ? "stopped: " : (failure.empty() ? "done: " : "before the error: "), stats.published,
               stats.events, stats.log_s(), stats.wall_s,
               stats.publish_failures ? fmt::format(", {} publish failures", stats.publish_failures) : "");
  std::fflush(stdout);
  if (!failure.empty()) throw std::runtime_error(failure);
}

}  // namespace

void AddReplayLogCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "replay-log", "Republish an LCM log so detect and fit can be rerun without video");
  auto o = std::make_shared<ReplayLogOptions>();
  cmd->add_option("log", o->log, "LCM log (.lcm), as written by --log or lcm-logger")->required();
  cmd->add_option("--speed", o->replay.speed,
                  "pace at this multiple of the logged timing (0: as fast as possible)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--channels", o->replay.channels_regex,
                  "republish only channels matching this regular expression")
      ->capture_default_str();
  AddLcmUrlFlag(cmd, &o->lcm_url);
  cmd->add_flag("--quiet,-q", o->quiet, "print only the final line");
  cmd->footer(
      "Example (with `bouncefit detect` and `bouncefit fit` listening in other terminals):\n"
      "  bouncefit replay-log out/sample/session.lcm");
  cmd->callback([o] { Run(*o); });
}

}  // namespace bouncefit::cli
