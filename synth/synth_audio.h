#pragma once
// The sound of a synth clip: a click at each impact (louder for faster impacts) over room
// noise, optionally with chatter (voices) and mains hum, optionally shifted against the
// picture as phones record it. Pure: samples in, samples out; synth/synth_audio_mux.h puts
// them into the clip.
#include <cstdint>
#include <string>
#include <vector>

namespace bouncefit {

struct SynthAudioConfig {
  int sample_rate = 44100;
  double offset_s = 0;          // the sound lags the picture by this (negative: leads), s
  // Click peak amplitude (full scale 1) at 1 m/s, growing as the impact speed to
  // click_exponent: the shared real clips' clicks grow as speed^1.1 to speed^1.8.
  double click_at_1mps = 0.08;
  double click_exponent = 1.3;
  double click_decay_s = 0.0015;
  double noise_rms = 0.002;     // room noise (about -54 dBFS)
  bool chatter = false;         // voices in the room: voiced syllables and hissed consonants
  double chatter_rms = 0.02;    // background voices, about -34 dBFS
  bool hum = false;             // mains hum at hum_hz and its harmonics
  double hum_hz = 50;
  double hum_rms = 0.05;
  // Clicks that are no impact of the ball (a hand tapping it, a knock), picture time, s: each
  // as loud as an impact at 1 m/s.
  std::vector<double> extra_clicks_s;
  uint64_t seed = 1;

  std::string Validate() const;  // empty when valid, else a one-line reason
};

// Samples from t = 0 to duration_s of the file's clock (the picture's t = 0 is the first
// frame); an impact at picture time t (speed v, m/s) clicks at t + offset_s.
// Throws std::invalid_argument for a bad config or mismatched impact lists.
std::vector<float> RenderSynthAudio(const SynthAudioConfig& config, double duration_s,
                                    const std::vector<double>& impact_times_s,
                                    const std::vector<double>& impact_speeds_mps);

}  // namespace bouncefit
