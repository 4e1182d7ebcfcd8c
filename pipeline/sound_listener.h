#pragma once
// The capture node's ears: decodes a clip's sound track paced with its video (or listens to
// a live microphone beside the camera) and turns each impact heard into an IMPACT message
// (source "audio") as the stream reaches its time; keeps the sound's envelope for
// waveform.csv. Fusing what was heard with what was seen is the detect node's
// (pipeline/sound_fusion.h).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bouncefit/impact_t.hpp"
#include "capture/alsa_microphone.h"

namespace bouncefit {

class AudioFileSource;
class ImpactDetector;
class MicrophoneReader;
struct AudioChunk;

class SoundListener {
 public:
  // A clip's sound (an empty path, or a clip without sound: enabled() false). Throws
  // std::runtime_error only for an unreadable file.
  explicit SoundListener(const std::string& clip);
  // A live microphone (its chunks stamped on CLOCK_MONOTONIC, as V4L2 cameras stamp frames).
  // Throws std::runtime_error with a one-line reason when it cannot be opened.
  explicit SoundListener(const AlsaMicrophoneConfig& mic);
  ~SoundListener();

  bool enabled() const { return source_ != nullptr || mic_ != nullptr; }
  const std::string& Describe() const { return description_; }

  // Decodes (or takes what the microphone heard) up to video time t_s (s since the first
  // frame, whose capture time is t0_utime); returns the impacts heard that became certain.
  std::vector<impact_t> AdvanceTo(double t_s, int64_t t0_utime);
  // The end of the stream: the rest of the clip's sound (or the microphone stopped), the
  // impacts still pending.
  std::vector<impact_t> Finish(int64_t t0_utime);

  // waveform.csv: the sound's peak |amplitude| per 5 ms on the video clock (nothing without sound).
  void WriteWaveformCsv(const std::filesystem::path& dir) const;

  double first_sample_t_s() const { return first_sample_t_s_; }  // video clock; NaN: none yet
  int64_t overruns() const;  // a microphone's lost periods
  double cpu_s() const { return cpu_s_; }

 private:
  void Listen(const AudioChunk& chunk, double shift_s, int64_t t0_utime, std::vector<impact_t>* out);
  void Envelope(const AudioChunk& chunk, double t0_s);

  static constexpr double kWaveBinS = 0.005;  // waveform.csv's window

  std::unique_ptr<AudioFileSource> source_;
  std::unique_ptr<MicrophoneReader> mic_;
  std::unique_ptr<ImpactDetector> detector_;
  std::string description_;
  bool ended_ = false;     // the clip's sound is decoded to its end
  bool finished_ = false;  // Finish() ran: nothing more is heard
  int next_index_ = 0;
  double decoded_to_s_ = -1e9;
  double first_sample_t_s_;
  std::vector<float> wave_peak_;  // per kWaveBinS window from wave_first_bin_
  int64_t wave_first_bin_ = 0;
  double cpu_s_ = 0;  // decoding + detecting, CPU seconds of the calling thread
};

}  // namespace bouncefit
