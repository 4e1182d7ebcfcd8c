#include "synth/synth_audio.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace bouncefit {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// A ball's click: a few damped resonances and a damped noise burst, full amplitude at the
// first sample (the impact), gone within a few decay times.
void AddClick(std::vector<float>* out, int rate, double t_s, double amplitude, double decay_s,
              std::mt19937_64& rng) {
  const int64_t first = static_cast<int64_t>(std::ceil(t_s * rate));
  const int64_t length = static_cast<int64_t>(8 * decay_s * rate);
  std::uniform_real_distribution<double> freq(2500, 9000), phase(0, kTwoPi);
  std::normal_distribution<double> gauss(0, 1);
  double f[3], p[3];
  for (int k = 0; k < 3; ++k) f[k] = freq(rng), p[k] = phase(rng);
  for (int64_t n = 0; n < length; ++n) {
    const int64_t i = first + n;
    if (i < 0) continue;
    if (i >= static_cast<int64_t>(out->size())) break;
    const double tau = (i - t_s * rate) / rate;  // since the impact, >= 0
    const double env = std::exp(-tau / decay_s);
    double v = 0.5 * gauss(rng);
    for (int k = 0; k < 3; ++k) v += 0.5 * std::cos(kTwoPi * f[k] * tau + p[k]);
    // Normalised so the first samples reach about `amplitude`.
    (*out)[i] += static_cast<float>(amplitude * env * v / 1.2);
  }
}

// Voices: syllables of a harmonic voice with a gliding pitch, separated by pauses, and
// hissed consonants (noise with a ~20 ms attack) between some of them.
void AddChatter(std::vector<float>* out, int rate, double rms, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> gauss(0, 1);
  const double seconds = static_cast<double>(out->size()) / rate;
  double t = 0.05 * u(rng);
  while (t < seconds) {
    const double syllable = 0.12 + 0.18 * u(rng);
    const double f0 = 100 + 140 * u(rng), glide = (u(rng) - 0.5) * 60;
    const double formant = 400 + 800 * u(rng);
    const int64_t a = static_cast<int64_t>(t * rate);
    const int64_t b = std::min<int64_t>(out->size(), static_cast<int64_t>((t + syllable) * rate));
    double phase = 0;
    for (int64_t i = a; i < b; ++i) {
      const double s = static_cast<double>(i - a) / rate;
      const double env = std::pow(std::sin(std::numbers::pi * s / syllable), 2);
      const double f = f0 + glide * s / syllable;
      phase += kTwoPi * f / rate;
      double v = 0;
      // Glottal source falling 12 dB per octave, shaped by two formants.
      for (int h = 1; h * f < 5000; ++h)
        v += std::sin(h * phase) / (h * h) *
             (1 + 4 * std::exp(-std::pow((h * f - formant) / 300, 2)) +
              2 * std::exp(-std::pow((h * f - 2.5 * formant) / 500, 2)));
      (*out)[i] += static_cast<float>(rms * env * v);
    }
    t += syllable;
    if (u(rng) < 0.4) {  // a hissed consonant ("s", "f"): broadband but slow to rise
      const double len = 0.06 + 0.08 * u(rng);
      const int64_t c = std::min<int64_t>(out->size(), static_cast<int64_t>((t + len) * rate));
      for (int64_t i = static_cast<int64_t>(t * rate); i < c; ++i) {
        const double s = static_cast<double>(i) / rate - t;
        const double env = std::min(1.0, s / 0.02) * std::min(1.0, (len - s) / 0.02);
        (*out)[i] += static_cast<float>(0.3 * rms * env * gauss(rng));
      }
      t += len;
    }
    t += 0.03 + 0.25 * u(rng);  // pause
  }
}

}  // namespace

std::string SynthAudioConfig::Validate() const {
  if (sample_rate < 8000 || sample_rate > 192000) return "sound sample rate must be 8-192 kHz";
  if (!std::isfinite(offset_s) || std::abs(offset_s) > 5) return "sound offset must be within +-5 s";
  if (!(click_at_1mps > 0 && click_at_1mps <= 1)) return "click level must be in (0, 1] at 1 m/s";
  if (!(click_exponent >= 0.5 && click_exponent <= 3)) return "click exponent must be in [0.5, 3]";
  if (!(click_decay_s > 0 && click_decay_s <= 0.05)) return "click decay must be in (0, 50] ms";
  if (!(noise_rms >= 0 && noise_rms < 0.5)) return "room noise must be in [0, 0.5) full scale";
  if (!(chatter_rms >= 0 && chatter_rms < 0.5)) return "chatter level must be in [0, 0.5)";
  if (!(hum_hz > 0 && hum_hz < 1000)) return "hum frequency must be in (0, 1000) Hz";
  if (!(hum_rms >= 0 && hum_rms < 0.5)) return "hum level must be in [0, 0.5)";
  for (double t : extra_clicks_s)
    if (!(std::isfinite(t) && t >= 0)) return "extra clicks must be at 0 s or later";
  return "";
}

std::vector<float> RenderSynthAudio(const SynthAudioConfig& c, double duration_s,
                                    const std::vector<double>& impact_times_s,
                                    const std::vector<double>& impact_speeds_mps) {
  if (const std::string e = c.Validate(); !e.empty()) throw std::invalid_argument(e);
  if (impact_times_s.size() != impact_speeds_mps.size())
    throw std::invalid_argument("sound: one impact speed per impact time is needed");
  if (!(duration_s > 0)) throw std::invalid_argument("sound: duration must be > 0 s");
  std::vector<float> out(static_cast<size_t>(std::ceil(duration_s * c.sample_rate)), 0.0f);
  std::mt19937_64 rng(c.seed * 0x9e3779b97f4a7c15ULL + 12345);
  std::normal_distribution<double> gauss(0, 1);
  for (auto& s : out) s = static_cast<float>(c.noise_rms * gauss(rng));
  if (c.hum) {
    const double amp = c.hum_rms * std::sqrt(2.0) / std::sqrt(1 + 0.25 + 0.0625);
    for (size_t i = 0; i < out.size(); ++i) {
      const double ph = kTwoPi * c.hum_hz * i / c.sample_rate;
      out[i] += static_cast<float>(amp * (std::sin(ph) + 0.5 * std::sin(2 * ph + 1) +
                                          0.25 * std::sin(3 * ph + 2)));
    }
  }
  if (c.chatter) AddChatter(&out, c.sample_rate, c.chatter_rms, rng);
  for (size_t k = 0; k < impact_times_s.size(); ++k) {
    const double amp =
        std::min(0.9, c.click_at_1mps * std::pow(std::abs(impact_speeds_mps[k]), c.click_exponent));
    AddClick(&out, c.sample_rate, impact_times_s[k] + c.offset_s, amp, c.click_decay_s, rng);
  }
  for (double t : c.extra_clicks_s)
    AddClick(&out, c.sample_rate, t + c.offset_s, std::min(0.9, c.click_at_1mps), c.click_decay_s, rng);
  for (auto& s : out) s = std::clamp(s, -1.0f, 1.0f);
  return out;
}

}  // namespace bouncefit
