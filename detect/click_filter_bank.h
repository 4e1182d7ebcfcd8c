#pragma once
// The filters an impact detector listens through: a high-pass that removes hum and most of
// speech's energy, then band-passes splitting what is left into bands a fraction of an
// octave wide. A ball's click spreads over all of them at once; a voice, a whistle or a
// hum sits in a few.
#include <cstddef>
#include <vector>

namespace bouncefit {

// A second-order IIR section (direct form I).
struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
  double x1 = 0, x2 = 0, y1 = 0, y2 = 0;

  double Step(double x) {
    const double y = b0 * x + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
    x2 = x1, x1 = x, y2 = y1, y1 = y;
    return y;
  }
  // RBJ cookbook designs at a sample rate: a Butterworth high-pass, and a band-pass of 0 dB
  // peak gain between two edges.
  static Biquad HighPass(double fc_hz, double rate_hz);
  static Biquad BandPass(double lo_hz, double hi_hz, double rate_hz);
};

class ClickFilterBank {
 public:
  // Bands from highpass_hz up to top_hz (at most 0.45 of the rate), bands_per_octave to an
  // octave; at least one band. highpass_hz 0: no high-pass.
  ClickFilterBank(double highpass_hz, double top_hz, double bands_per_octave, int rate_hz);

  int bands() const { return static_cast<int>(bands_.size()); }
  double band_low_hz(int b) const { return edges_[b]; }
  double band_high_hz(int b) const { return edges_[b + 1]; }

  // One sample through the high-pass.
  double HighPass(double x) { return highpass_.Step(x); }
  // n high-passed samples through every band: adds each band's sum of squares to
  // energy[b] (energy holds bands() values). Band by band, so each filter's state stays
  // in registers.
  void AddBandEnergies(const double* y, int n, double* energy);

 private:
  Biquad highpass_;
  std::vector<Biquad> bands_;
  std::vector<double> edges_;
};

}  // namespace bouncefit
