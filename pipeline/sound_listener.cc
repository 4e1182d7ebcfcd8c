#include "pipeline/sound_listener.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <stdexcept>

#include "capture/microphone_reader.h"
#include "detect/impact_detector.h"
#include "replay/audio_file_source.h"

namespace bouncefit {
namespace {

double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

impact_t HeardMessage(const AudioImpact& i, int index, int64_t t0_utime) {
  impact_t m{};
  m.utime = t0_utime + std::llround(i.t_s * 1e6);
  m.index = index;
  m.source = "audio";
  m.strength = i.strength;
  m.confidence = i.confidence;
  m.snr_db = i.snr_db;
  return m;
}

}  // namespace

SoundListener::SoundListener(const std::string& clip) : first_sample_t_s_(NAN) {
  if (clip.empty()) {
    description_ = "no sound";
    return;
  }
  auto source = std::make_unique<AudioFileSource>(clip);
  if (!source->has_audio()) {
    description_ = "no sound track";
    return;
  }
  description_ = source->Describe();
  detector_ = std::make_unique<ImpactDetector>(ImpactDetectorConfig{}, source->sample_rate());
  source_ = std::move(source);
}

SoundListener::SoundListener(const AlsaMicrophoneConfig& mic) : first_sample_t_s_(NAN) {
  mic_ = std::make_unique<MicrophoneReader>(mic);
  description_ = mic_->Describe();
  detector_ = std::make_unique<ImpactDetector>(ImpactDetectorConfig{}, mic_->sample_rate());
}

SoundListener::~SoundListener() = default;

int64_t SoundListener::overruns() const { return mic_ ? mic_->overruns() : 0; }

void SoundListener::Listen(const AudioChunk& chunk, double shift_s, int64_t t0_utime,
                           std::vector<impact_t>* out) {
  const double t0 = chunk.t0_s - shift_s;
  if (std::isnan(first_sample_t_s_)) first_sample_t_s_ = t0;
  Envelope(chunk, t0);
  std::vector<AudioImpact> heard = detector_->Push(t0, chunk.samples.data(), chunk.samples.size());
  decoded_to_s_ = t0 + static_cast<double>(chunk.samples.size()) / chunk.sample_rate;
  for (const AudioImpact& i : heard) out->push_back(HeardMessage(i, next_index_++, t0_utime));
}

void SoundListener::Envelope(const AudioChunk& chunk, double t0_s) {
  const size_t n = chunk.samples.size();
  const double rate = chunk.sample_rate;
  for (size_t i = 0; i < n;) {
    const auto bin = static_cast<int64_t>(std::floor((t0_s + i / rate) / kWaveBinS));
    const auto end = std::clamp<size_t>(
        static_cast<size_t>(std::ceil(((bin + 1) * kWaveBinS - t0_s) * rate)), i + 1, n);
    float peak = 0;
    for (size_t k = i; k < end; ++k) peak = std::max(peak, std::abs(chunk.samples[k]));
    if (wave_peak_.empty()) wave_first_bin_ = bin;
    if (bin >= wave_first_bin_) {
      const auto at = static_cast<size_t>(bin - wave_first_bin_);
      if (at >= wave_peak_.size()) wave_peak_.resize(at + 1, 0.0f);
      wave_peak_[at] = std::max(wave_peak_[at], peak);
    }
    i = end;
  }
}

std::vector<impact_t> SoundListener::AdvanceTo(double t_s, int64_t t0_utime) {
  std::vector<impact_t> out;
  if (!enabled() || ended_) return out;
  const double cpu0 = CpuSeconds();
  if (mic_) {
    // Live: whatever the microphone heard so far; its CLOCK_MONOTONIC is the frames' clock.
    for (const AudioChunk& chunk : mic_->Take()) Listen(chunk, t0_utime * 1e-6, t0_utime, &out);
  } else {
    AudioChunk chunk;
    while (decoded_to_s_ < t_s) {
      if (!source_->Next(&chunk)) {
        ended_ = true;
        break;
      }
      Listen(chunk, 0, t0_utime, &out);
    }
  }
  cpu_s_ += CpuSeconds() - cpu0;
  return out;
}

std::vector<impact_t> SoundListener::Finish(int64_t t0_utime) {
  std::vector<impact_t> out;
  if (!enabled() || finished_) return out;
  finished_ = true;
  if (mic_) {
    mic_->Stop();
    out = AdvanceTo(0, t0_utime);
  } else {
    out = AdvanceTo(1e300, t0_utime);
  }
  ended_ = true;
  for (const AudioImpact& i : detector_->Finish()) out.push_back(HeardMessage(i, next_index_++, t0_utime));
  return out;
}

void SoundListener::WriteWaveformCsv(const std::filesystem::path& dir) const {
  if (wave_peak_.empty()) return;
  std::ofstream f(dir / "waveform.csv", std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + (dir / "waveform.csv").string() + "'");
  f << "t_s,peak\n";
  for (size_t k = 0; k < wave_peak_.size(); ++k)
    f << fmt::format("{:.4f},{:.4f}\n", (wave_first_bin_ + static_cast<int64_t>(k)) * kWaveBinS,
                     wave_peak_[k]);
}

}  // namespace bouncefit
