#pragma once
// The clocks a node reads (a core never does: time is its input): the steady clock for
// timeouts and durations, the wall clock for an LCM log's receive times.
#include <chrono>
#include <cstdint>

namespace bouncefit {

inline int64_t SteadyMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

inline int64_t WallMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace bouncefit
