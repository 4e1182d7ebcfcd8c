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

namespace {

// The mean of a window of steps when they are of one period: alike (a container's tick rounds
// a 1/240 s step on a 1/600 s tick to 3.3 and 5 ms in turn, neither alone within one_period of
// the period) and their mean within one_period of the reference; else 0.
template <typename It>
double OnePeriodMean(It begin, It end, double reference_us, double alike, double one_period) {
  const auto [lo, hi] = std::minmax_element(begin, end);
  if (static_cast<double>(*hi) > alike * static_cast<double>(*lo)) return 0;
  double sum = 0;
  for (It i = begin; i != end; ++i) sum += static_cast<double>(*i);
  const double mean = sum / static_cast<double>(end - begin);
  return mean * one_period >= reference_us && mean <= one_period * reference_us ? mean : 0;
}

constexpr size_t kPeriodWindow = 12;

}  // namespace

double CapturePeriodOfStamps(const std::vector<int64_t>& stamps, double rough_us, const CaptureClockConfig& config) {
  std::vector<int64_t> steps;
  for (size_t i = 1; i < stamps.size(); ++i) steps.push_back(stamps[i] - stamps[i - 1]);
  std::vector<double> means;
  for (size_t i = 0; i + kPeriodWindow <= steps.size(); ++i) {
    const auto from = steps.begin() + static_cast<std::ptrdiff_t>(i);
    if (const double m = OnePeriodMean(from, from + kPeriodWindow, rough_us, config.alike, config.one_period); m > 0)
      means.push_back(m);
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
    window_.clear();
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
      window_.clear();
    }
  }
  // Until the file is known to hold slow motion, every step as stamped: a lone long step is a
  // picture dropped, and a run's first steps are read again once the run shows.
  taken_us_ += d;
  if (!CountSlowed(step, pictures)) {
    // The mean of the last steps when they are of one period: a tick's rounding averages out,
    // a ramp's lengthening steps (which would lengthen the period and shrink every scale with
    // it) are not alike or not of one period. Judged against the period as found, not the
    // mean: a mean pulled by the tick's rounding must not narrow what it takes in.
    window_.push_back(step);
    if (window_.size() > kPeriodWindow) window_.pop_front();
    if (period_us_ > 0 && window_.size() == kPeriodWindow) {
      if (const double m = OnePeriodMean(window_.begin(), window_.end(), anchor_us_, config_.alike, config_.one_period);
          m > 0) {
        period_sum_us_ += m;
        period_us_ = period_sum_us_ / static_cast<double>(++period_steps_);
      }
    }
  } else {
    window_.clear();
  }
  return last_taken();
}

}  // namespace bouncefit
