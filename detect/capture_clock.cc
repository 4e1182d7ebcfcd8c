#include "detect/capture_clock.h"

#include <cmath>
#include <cstdlib>

namespace bouncefit {

int64_t CaptureClock::Add(int64_t utime) {
  if (!started_) {
    started_ = true;
    last_ = taken_ = utime;
    return taken_;
  }
  if (utime <= last_) return taken_;
  const int64_t step = utime - last_;
  last_ = utime;
  // A container's tick rounds a step by a few microseconds: alike within a share and 2 us.
  const bool alike = std::abs(static_cast<double>(step - run_step_)) <=
                     config_.alike * static_cast<double>(run_step_) + 2;
  run_ = run_step_ > 0 && alike ? run_ + 1 : 1;
  if (run_ == 1) run_step_ = step;
  if (run_ >= config_.min_run && run_step_ <= config_.max_capture_period_s * 1e6 &&
      (period_us_ == 0 || run_step_ < period_us_ * (1 - config_.alike)))
    period_us_ = static_cast<double>(run_step_);
  if (period_us_ > 0 && step >= config_.min_slowdown * period_us_) {
    ++slowed_steps_;
    slowed_stamp_us_ += step;
    max_slowdown_ = std::max(max_slowdown_, step / period_us_);
    taken_ += std::llround(period_us_);
  } else {
    taken_ += step;
  }
  return taken_;
}

}  // namespace bouncefit
