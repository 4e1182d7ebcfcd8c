#include "detect/capture_clock.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace bouncefit {

int64_t CaptureClock::Add(int64_t utime) {
  if (!started_) {
    started_ = true;
    last_ = utime;
    taken_us_ = static_cast<double>(utime);
    return utime;
  }
  if (utime <= last_) return last_taken();
  const int64_t step = utime - last_;
  last_ = utime;
  recent_.push_back(step);
  if (static_cast<int>(recent_.size()) > config_.min_run) recent_.pop_front();
  if (static_cast<int>(recent_.size()) == config_.min_run) {
    const auto [lo, hi] = std::minmax_element(recent_.begin(), recent_.end());
    double mean = 0;
    for (int64_t d : recent_) mean += static_cast<double>(d) / config_.min_run;
    // A shorter period than the one known (the file began slowed) starts the mean again.
    if (*hi <= config_.alike * *lo && mean <= config_.max_capture_period_s * 1e6 &&
        (period_us_ == 0 || mean < period_us_ / config_.alike)) {
      period_us_ = mean;
      ++period_changes_;
      period_sum_us_ = 0;
      period_steps_ = 0;
    }
  }
  const double d = static_cast<double>(step);
  if (period_us_ > 0 && d >= config_.min_slowdown * period_us_) {
    ++slowed_steps_;
    slowed_stamp_us_ += step;
    max_slowdown_ = std::max(max_slowdown_, d / period_us_);
    taken_us_ += period_us_;
  } else {
    taken_us_ += d;
    if (period_us_ > 0 && d * config_.alike >= period_us_ && d <= config_.alike * period_us_) {
      period_sum_us_ += d;
      ++period_steps_;
      if (period_steps_ >= config_.min_run) period_us_ = period_sum_us_ / static_cast<double>(period_steps_);
    }
  }
  return last_taken();
}

}  // namespace bouncefit
