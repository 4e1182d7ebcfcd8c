#pragma once
// A percentile of the last `window` energies pushed, on a 0.1 dB histogram from -120 to
// +20 dB full scale: a push moves the percentile's bin by a few steps, so tracking a noise
// floor costs about the same per block whatever the window's length.
#include <cstdint>
#include <vector>

namespace bouncefit {

class SlidingPercentile {
 public:
  // window: how many of the latest values count (>= 1); percentile in (0, 1).
  SlidingPercentile(int window, double percentile);

  void Push(double energy);
  // The percentile of the values in the window as an energy (0 before the first push).
  double Value() const;
  int size() const { return count_; }

 private:
  static int Bin(double energy);
  void Settle();

  static constexpr double kLowDb = -120, kBinsPerDb = 10;
  static constexpr int kBins = 1400;
  double percentile_;
  std::vector<int> hist_ = std::vector<int>(kBins, 0);
  std::vector<int16_t> ring_;  // the window's bins, oldest at head_ once full
  int head_ = 0, count_ = 0;
  int bin_ = 0;    // the bin holding the percentile
  int below_ = 0;  // values in bins below bin_
  int value_bin_ = -1;  // the bin value_ (its energy) was computed for
  double value_ = 0;
};

}  // namespace bouncefit
