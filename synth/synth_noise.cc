#include "synth/synth_noise.h"

#include <cmath>
#include <numbers>

namespace bouncefit {
namespace {

uint64_t SplitMix64(uint64_t* x) {
  uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

inline uint64_t Rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

// Inverse of the standard normal CDF (Acklam's rational approximation, then one Halley
// refinement step: ~1e-15 relative).
double NormalQuantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                             -2.759285104469687e+02, 1.383577518672690e+02,
                             -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                             -1.556989798598866e+02, 6.680131188771972e+01,
                             -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                             -2.400758277161838e+00, -2.549732539343734e+00,
                             4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                             2.445134137142996e+00, 3.754408661907416e+00};
  const double plow = 0.02425;
  double x;
  if (p < plow) {
    const double q = std::sqrt(-2 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else if (p <= 1 - plow) {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  } else {
    const double q = std::sqrt(-2 * std::log(1 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2 * std::numbers::pi) * std::exp(x * x / 2);
  return x - u / (1 + x * u / 2);
}

}  // namespace

SynthNoise::SynthNoise(double sigma, uint64_t seed) : sigma_(sigma) {
  uint64_t x = seed;
  for (auto& s : s_) s = SplitMix64(&x);
  if (sigma_ <= 0) return;
  table_.resize(65536);
  for (int i = 0; i < 65536; ++i)
    table_[i] = static_cast<int16_t>(std::lround(sigma_ * NormalQuantile((i + 0.5) / 65536.0)));
}

uint64_t SynthNoise::Next() {  // xoshiro256**
  const uint64_t result = Rotl(s_[1] * 5, 7) * 9;
  const uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = Rotl(s_[3], 45);
  return result;
}

void SynthNoise::Add(cv::Mat* image) {
  if (sigma_ <= 0) return;
  CV_Assert(image->depth() == CV_8U);
  const int n = image->cols * image->channels();
  for (int y = 0; y < image->rows; ++y) {
    uchar* p = image->ptr<uchar>(y);
    int i = 0;
    for (; i + 4 <= n; i += 4) {
      uint64_t r = Next();
      for (int k = 0; k < 4; ++k, r >>= 16) {
        const int v = p[i + k] + table_[r & 0xFFFF];
        p[i + k] = static_cast<uchar>(v < 0 ? 0 : (v > 255 ? 255 : v));
      }
    }
    for (uint64_t r = Next(); i < n; ++i, r >>= 16) {
      const int v = p[i] + table_[r & 0xFFFF];
      p[i] = static_cast<uchar>(v < 0 ? 0 : (v > 255 ? 255 : v));
    }
  }
}

}  // namespace bouncefit
