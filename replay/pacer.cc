#include "replay/pacer.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

namespace bouncefit {
namespace {

class SteadyClock final : public PacerClock {
 public:
  int64_t NowMicros() override {
    return std::chrono::duration_cast<std::chrono::microseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  void SleepUntilMicros(int64_t deadline) override {
    std::this_thread::sleep_until(
        std::chrono::steady_clock::time_point(std::chrono::microseconds(deadline)));
  }
};

}  // namespace

PacerClock& SteadyPacerClock() {
  static SteadyClock clock;
  return clock;
}

Pacer::Pacer(double speed, PacerClock& clock) : speed_(speed), clock_(clock) {
  if (!std::isfinite(speed) || speed < 0)
    throw std::invalid_argument("speed must be >= 0 (0 = as fast as possible), got " +
                                std::to_string(speed));
}

int64_t Pacer::WaitFor(int64_t utime) {
  if (speed_ == 0) return 0;
  const int64_t now = clock_.NowMicros();
  if (!anchored_ || utime < last_) {
    anchored_ = true;
    wall0_ = now;
    stream0_ = utime;
    last_ = utime;
    return 0;
  }
  last_ = utime;
  const int64_t due = wall0_ + std::llround(double(utime - stream0_) / speed_);
  if (due > now) {
    clock_.SleepUntilMicros(due);
    return 0;
  }
  const int64_t late = now - due;
  if (late > max_late_) max_late_ = late;
  return late;
}

}  // namespace bouncefit
