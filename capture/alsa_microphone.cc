#include "capture/alsa_microphone.h"

#include <alsa/asoundlib.h>
#include <time.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace bouncefit {
namespace {

double MonotonicNow() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

}  // namespace

struct AlsaMicrophone::Impl {
  snd_pcm_t* pcm = nullptr;
  snd_config_t* config = nullptr;
  std::vector<int16_t> buffer;
  snd_pcm_uframes_t period = 0;
  ~Impl() {
    if (pcm) snd_pcm_close(pcm);
    if (config) snd_config_delete(config);
  }
};

AlsaMicrophone::AlsaMicrophone(AlsaMicrophoneConfig config)
    : impl_(std::make_unique<Impl>()), config_(std::move(config)) {
  const std::string where = "audio device '" + config_.device + "'";
  if (config_.sample_rate < 8000 || config_.sample_rate > 192000)
    throw std::invalid_argument("audio sample rate must be 8-192 kHz");
  if (!(config_.period_s > 0.001 && config_.period_s < 0.5))
    throw std::invalid_argument("audio period must be in (1, 500) ms");
  int rc = 0;
  if (!config_.config_text.empty()) {
    snd_input_t* in = nullptr;
    snd_config_top(&impl_->config);
    rc = snd_input_buffer_open(&in, config_.config_text.c_str(), config_.config_text.size());
    if (rc >= 0) rc = snd_config_load(impl_->config, in);
    if (in) snd_input_close(in);
    if (rc < 0) throw std::runtime_error("bad ALSA configuration for " + where + ": " + snd_strerror(rc));
    rc = snd_pcm_open_lconf(&impl_->pcm, config_.device.c_str(), SND_PCM_STREAM_CAPTURE, 0,
                            impl_->config);
  } else {
    rc = snd_pcm_open(&impl_->pcm, config_.device.c_str(), SND_PCM_STREAM_CAPTURE, 0);
  }
  if (rc < 0) throw std::runtime_error("cannot open " + where + ": " + snd_strerror(rc));

  snd_pcm_hw_params_t* hw = nullptr;
  snd_pcm_hw_params_alloca(&hw);
  snd_pcm_hw_params_any(impl_->pcm, hw);
  unsigned rate = static_cast<unsigned>(config_.sample_rate);
  snd_pcm_uframes_t period = static_cast<snd_pcm_uframes_t>(config_.period_s * rate);
  int dir = 0;
  if ((rc = snd_pcm_hw_params_set_access(impl_->pcm, hw, SND_PCM_ACCESS_RW_INTERLEAVED)) < 0 ||
      (rc = snd_pcm_hw_params_set_format(impl_->pcm, hw, SND_PCM_FORMAT_S16_LE)) < 0 ||
      (rc = snd_pcm_hw_params_set_channels(impl_->pcm, hw, 1)) < 0 ||
      (rc = snd_pcm_hw_params_set_rate_near(impl_->pcm, hw, &rate, &dir)) < 0 ||
      (rc = snd_pcm_hw_params_set_period_size_near(impl_->pcm, hw, &period, &dir)) < 0 ||
      (rc = snd_pcm_hw_params(impl_->pcm, hw)) < 0)
    throw std::runtime_error(where + " refuses mono 16-bit capture at " +
                             std::to_string(config_.sample_rate) + " Hz (try plughw:): " +
                             snd_strerror(rc));
  rate_ = static_cast<int>(rate);
  impl_->period = period;
  impl_->buffer.resize(period);
  if ((rc = snd_pcm_prepare(impl_->pcm)) < 0 || (rc = snd_pcm_start(impl_->pcm)) < 0)
    throw std::runtime_error("cannot start " + where + ": " + snd_strerror(rc));
}

AlsaMicrophone::~AlsaMicrophone() = default;

std::string AlsaMicrophone::Describe() const {
  return "ALSA " + config_.device + " " + std::to_string(rate_) + " Hz mono";
}

bool AlsaMicrophone::Next(AudioChunk* chunk) {
  snd_pcm_sframes_t n = snd_pcm_readi(impl_->pcm, impl_->buffer.data(), impl_->period);
  if (n == -EPIPE) {  // overrun: samples were lost, so the sample count no longer tells time
    ++overruns_;
    anchored_ = false;
    if (snd_pcm_prepare(impl_->pcm) < 0 || snd_pcm_start(impl_->pcm) < 0) return false;
    n = snd_pcm_readi(impl_->pcm, impl_->buffer.data(), impl_->period);
  }
  if (n < 0) n = snd_pcm_recover(impl_->pcm, static_cast<int>(n), 1) < 0 ? n : 0;
  if (n < 0) return false;
  const double now = MonotonicNow();
  if (!anchored_) {
    // The samples just read, and any still waiting, were heard before now.
    snd_pcm_sframes_t waiting = 0;
    if (snd_pcm_delay(impl_->pcm, &waiting) < 0) waiting = 0;
    anchor_s_ = now - static_cast<double>(n + waiting) / rate_;
    frames_read_ = 0;
    anchored_ = true;
  }
  chunk->sample_rate = rate_;
  chunk->t0_s = anchor_s_ + static_cast<double>(frames_read_) / rate_;
  chunk->samples.resize(static_cast<size_t>(n));
  for (snd_pcm_sframes_t i = 0; i < n; ++i) chunk->samples[i] = impl_->buffer[i] / 32768.0f;
  frames_read_ += n;
  if (config_.pace) {  // the last sample read was heard at anchor + frames / rate
    const double due = anchor_s_ + static_cast<double>(frames_read_) / rate_;
    const double wait = due - MonotonicNow();
    if (wait > 0) {
      timespec ts{static_cast<time_t>(wait), static_cast<long>((wait - std::floor(wait)) * 1e9)};
      nanosleep(&ts, nullptr);
    }
  }
  return true;
}

}  // namespace bouncefit
