#pragma once
// Fast seeded Gaussian sensor noise for synth frames: a 65536-entry table of Gaussian
// quantiles indexed by 16 random bits (xoshiro256**), so a 640x480 frame costs ~1 ms.
// Deterministic for a seed: the same sequence of frames gets the same noise.
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace bouncefit {

class SynthNoise {
 public:
  // sigma in grey levels (>= 0; 0 adds nothing).
  SynthNoise(double sigma, uint64_t seed);
  // Adds independent noise to every channel of every pixel of a CV_8U image, saturating.
  void Add(cv::Mat* image);

 private:
  uint64_t Next();
  double sigma_;
  uint64_t s_[4];
  std::vector<int16_t> table_;
};

}  // namespace bouncefit
