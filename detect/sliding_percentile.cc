#include "detect/sliding_percentile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {

SlidingPercentile::SlidingPercentile(int window, double percentile)
    : percentile_(percentile), ring_(static_cast<size_t>(std::max(window, 1)), 0) {
  if (window < 1 || !(percentile > 0 && percentile < 1))
    throw std::invalid_argument("sliding percentile: window must be >= 1 and percentile in (0, 1)");
}

int SlidingPercentile::Bin(double energy) {
  const double db = 10 * std::log10(std::max(energy, 1e-30));
  return std::clamp(static_cast<int>(std::lround((db - kLowDb) * kBinsPerDb)), 0, kBins - 1);
}

void SlidingPercentile::Push(double energy) {
  const int b = Bin(energy);
  const int window = static_cast<int>(ring_.size());
  if (count_ == window) {
    const int old = ring_[head_];
    --hist_[old];
    if (old < bin_) --below_;
  } else {
    ++count_;
  }
  ring_[head_] = static_cast<int16_t>(b);
  head_ = (head_ + 1) % window;
  ++hist_[b];
  if (b < bin_) ++below_;
  Settle();
}

void SlidingPercentile::Settle() {
  // bin_ holds the k-th smallest value: below_ <= k < below_ + hist_[bin_].
  const int k = static_cast<int>(percentile_ * (count_ - 1));
  while (bin_ > 0 && below_ > k) below_ -= hist_[--bin_];
  while (bin_ < kBins - 1 && below_ + hist_[bin_] <= k) below_ += hist_[bin_++];
  if (bin_ != value_bin_) value_bin_ = bin_, value_ = std::pow(10.0, (kLowDb + bin_ / kBinsPerDb) / 10);
}

double SlidingPercentile::Value() const {
  return count_ == 0 ? 0 : value_;
}

}  // namespace bouncefit
