#pragma once
// A stretch of mono sound samples with the time of the first one, from a clip's sound track
// (replay/audio_file_source.h) or a microphone (capture/alsa_microphone.h).
#include <vector>

namespace bouncefit {

// samples[i] was heard at t0_s + i / sample_rate.
struct AudioChunk {
  double t0_s = 0;
  int sample_rate = 0;
  std::vector<float> samples;  // mono, full scale +-1
};

}  // namespace bouncefit
