#include "detect/click_filter_bank.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bouncefit {

Biquad Biquad::HighPass(double fc, double rate) {
  Biquad q;
  if (!(fc > 0)) return q;
  const double w = 2 * std::numbers::pi * fc / rate;
  const double alpha = std::sin(w) / std::numbers::sqrt2;  // Q = 1/sqrt(2)
  const double cw = std::cos(w);
  const double a0 = 1 + alpha;
  q.b0 = (1 + cw) / 2 / a0;
  q.b1 = -(1 + cw) / a0;
  q.b2 = (1 + cw) / 2 / a0;
  q.a1 = -2 * cw / a0;
  q.a2 = (1 - alpha) / a0;
  return q;
}

Biquad Biquad::BandPass(double lo, double hi, double rate) {
  Biquad q;
  const double f0 = std::sqrt(lo * hi);
  const double w = 2 * std::numbers::pi * f0 / rate;
  const double octaves = std::log2(hi / lo);
  const double alpha = std::sin(w) * std::sinh(std::numbers::ln2 / 2 * octaves * w / std::sin(w));
  const double a0 = 1 + alpha;
  q.b0 = alpha / a0;
  q.b1 = 0;
  q.b2 = -alpha / a0;
  q.a1 = -2 * std::cos(w) / a0;
  q.a2 = (1 - alpha) / a0;
  return q;
}

ClickFilterBank::ClickFilterBank(double highpass_hz, double top_hz, double bands_per_octave, int rate) {
  highpass_ = Biquad::HighPass(std::min(highpass_hz, 0.45 * rate), rate);
  const double lo = std::clamp(highpass_hz, 50.0, 0.3 * rate);
  const double top = std::clamp(top_hz, lo * 1.2, 0.45 * rate);
  const int n = std::max(1, static_cast<int>(std::floor(bands_per_octave * std::log2(top / lo) + 1e-9)));
  const double step = std::pow(top / lo, 1.0 / n);  // n equal bands on a log scale
  for (int b = 0; b <= n; ++b) edges_.push_back(lo * std::pow(step, b));
  for (int b = 0; b < n; ++b) bands_.push_back(Biquad::BandPass(edges_[b], edges_[b + 1], rate));
}

void ClickFilterBank::AddBandEnergies(const double* y, int n, double* energy) {
  for (size_t b = 0; b < bands_.size(); ++b) {
    Biquad q = bands_[b];
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      const double v = q.Step(y[i]);
      sum += v * v;
    }
    bands_[b] = q;
    energy[b] += sum;
  }
}

}  // namespace bouncefit
