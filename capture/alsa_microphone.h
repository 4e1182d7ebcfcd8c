#pragma once
// A live microphone through ALSA (snd_pcm_*), beside the V4L2 camera: mono float chunks
// stamped on CLOCK_MONOTONIC, the clock of the camera's buffer timestamps, so heard impacts
// and seen frames share one time line (their fixed offset is estimated by the fusion).
//
// Each chunk's time comes from the sample count since the first read (the sound card's
// clock, free of scheduling jitter), anchored once at the first read: then minus what
// was already waiting in the buffer.
#include <cstdint>
#include <memory>
#include <string>

#include "capture/audio_chunk.h"

namespace bouncefit {

struct AlsaMicrophoneConfig {
  std::string device = "default";  // ALSA PCM name, e.g. hw:1,0 or plughw:1,0
  int sample_rate = 48000;         // asked for; the device may grant another
  double period_s = 0.01;          // samples per read
  // Optional ALSA configuration text defining `device` (e.g. a test's file plugin that
  // plays a recording as the microphone); empty: the system's configuration.
  std::string config_text;
  // Deliver no faster than real time. A sound card paces itself; a scripted device (the
  // file plugin over the null device) hands its whole recording over at once.
  bool pace = false;
};

class AlsaMicrophone {
 public:
  // Opens and starts the device. Throws std::runtime_error with a one-line reason
  // ("cannot open audio device 'hw:1,0': No such file or directory").
  explicit AlsaMicrophone(AlsaMicrophoneConfig config);
  ~AlsaMicrophone();
  AlsaMicrophone(const AlsaMicrophone&) = delete;
  AlsaMicrophone& operator=(const AlsaMicrophone&) = delete;

  int sample_rate() const { return rate_; }
  std::string Describe() const;
  // Blocks for the next period; t0_s in CLOCK_MONOTONIC seconds. Recovers from an
  // overrun (counted; the chunk after it is re-anchored). False on a fatal error.
  bool Next(AudioChunk* chunk);
  int64_t overruns() const { return overruns_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  AlsaMicrophoneConfig config_;
  int rate_ = 0;
  int64_t frames_read_ = 0;
  double anchor_s_ = 0;  // CLOCK_MONOTONIC time of sample 0
  bool anchored_ = false;
  int64_t overruns_ = 0;
};

}  // namespace bouncefit
