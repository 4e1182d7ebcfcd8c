#include "detect/capture_clock.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace bouncefit {

bool CaptureClock::CountSlowed(int64_t step, int64_t pictures) {
  const double d = static_cast<double>(step) / static_cast<double>(pictures);
  if (!(period_us_ > 0) || pictures > 1 || d < config_.min_slowdown * period_us_) {
    slowed_run_ = 0;
    return false;
  }
  ++slowed_steps_;
  slowed_stamp_us_ += step;
  max_slowdown_ = std::max(max_slowdown_, d / period_us_);
  longest_slowed_run_ = std::max(longest_slowed_run_, ++slowed_run_);
  return true;
}

double CapturePeriodOfStamps(const std::vector<int64_t>& stamps, double rough_us, double one_period) {
  constexpr size_t kWindow = 12;
  std::vector<double> means;
  size_t run = 0;  // steps of one period in a row, ending at step i
  for (size_t i = 1; i < stamps.size(); ++i) {
    const double d = static_cast<double>(stamps[i] - stamps[i - 1]);
    run = d * one_period >= rough_us && d <= one_period * rough_us ? run + 1 : 0;
    if (run >= kWindow)
      means.push_back(static_cast<double>(stamps[i] - stamps[i - kWindow]) / kWindow);
  }
  if (means.empty()) return rough_us;
  std::nth_element(means.begin(), means.begin() + static_cast<std::ptrdiff_t>(means.size() / 2), means.end());
  return means[means.size() / 2];
}

int64_t CaptureClock::Add(int64_t utime, int64_t index) {
  if (!started_) {
    started_ = true;
    last_ = utime;
    last_index_ = index;
    taken_us_ = static_cast<double>(utime);
    return utime;
  }
  if (utime <= last_) return last_taken();
  const int64_t step = utime - last_;
  // Pictures this step spans (1 when the index is unknown or starts again).
  const int64_t pictures = index >= 0 && last_index_ >= 0 && index > last_index_ ? index - last_index_ : 1;
  last_ = utime;
  last_index_ = index;
  const double d = static_cast<double>(step);
  if (config_.constant_capture && period_us_ > 0) {
    // Every picture one capture period after the one before, ramps and tick rounding alike.
    CountSlowed(step, pictures);
    taken_us_ += period_us_ * static_cast<double>(pictures);
    return last_taken();
  }
  if (pictures > 1) {  // no step of one picture: neither a period nor slow motion
    recent_.clear();
    CountSlowed(step, pictures);
    taken_us_ += d;
    return last_taken();
  }
  recent_.push_back(step);
  if (static_cast<int>(recent_.size()) > config_.min_run) recent_.pop_front();
  if (static_cast<int>(recent_.size()) == config_.min_run) {
    const auto [lo, hi] = std::minmax_element(recent_.begin(), recent_.end());
    double mean = 0;
    for (int64_t r : recent_) mean += static_cast<double>(r) / config_.min_run;
    // A shorter period than the one known (the file began slowed) starts the mean again.
    if (*hi <= config_.alike * *lo && mean <= config_.max_capture_period_s * 1e6 &&
        (period_us_ == 0 || mean < period_us_ / config_.alike)) {
      period_us_ = anchor_us_ = mean;
      ++period_changes_;
      period_sum_us_ = 0;
      period_steps_ = 0;
    }
  }
  // Until the file is known to hold slow motion, every step as stamped: a lone long step is a
  // picture dropped, and a run's first steps are read again once the run shows.
  taken_us_ += d;
  if (!CountSlowed(step, pictures)) {
    // The mean of the steps of one period: within a tick's rounding of it, not a ramp's
    // lengthening steps (which would lengthen the period and shrink every scale with it).
    // Judged against the period as found, not the mean: a mean pulled by the tick's rounding
    // must not narrow what it takes in.
    if (period_us_ > 0 && d * config_.one_period >= anchor_us_ && d <= config_.one_period * anchor_us_) {
      period_sum_us_ += d;
      ++period_steps_;
      if (period_steps_ >= 12) period_us_ = period_sum_us_ / static_cast<double>(period_steps_);
    }
  }
  return last_taken();
}

}  // namespace bouncefit
