#include "cli/stop_signal.h"

#include <csignal>

namespace bouncefit::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void OnStopSignal(int) { g_stop = true; }

}  // namespace

const std::atomic<bool>& StopOnSignal(bool hang_up) {
  struct sigaction sa {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  if (hang_up) ::sigaction(SIGHUP, &sa, nullptr);
  return g_stop;
}

}  // namespace bouncefit::cli
