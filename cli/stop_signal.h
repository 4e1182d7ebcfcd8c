#pragma once
// Ctrl-C and SIGTERM on a command that runs until stopped: they set a flag its loop reads,
// so it ends by writing what it recorded.
#include <atomic>

namespace bouncefit::cli {

// Sends SIGINT and SIGTERM to the flag it returns from now on; SIGHUP too with `hang_up` (a
// dashboard whose terminal closed restores it). No SA_RESTART: a wait on the bus returns at once.
const std::atomic<bool>& StopOnSignal(bool hang_up = false);

}  // namespace bouncefit::cli
