#include "detect/impact_detector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace bouncefit {
namespace {

double Db(double ratio) { return 10 * std::log10(std::max(ratio, 1e-30)); }

}  // namespace

std::string ImpactDetectorConfig::Validate() const {
  if (!(highpass_hz >= 0)) return "high-pass must be >= 0 Hz";
  if (!(block_s > 0 && block_s <= 0.01)) return "block must be in (0, 10] ms";
  if (!(floor_window_s >= 20 * block_s)) return "noise-floor window must hold >= 20 blocks";
  if (!(floor_percentile > 0 && floor_percentile < 1)) return "floor percentile must be in (0, 1)";
  if (!(min_snr_db > 0) || !(min_rise_db > 0) || !(decay_db > 0)) return "dB thresholds must be > 0";
  if (!(rise_window_s >= block_s)) return "rise window must be >= one block";
  if (!(attack_s >= block_s && attack_s <= 0.1)) return "attack must be one block to 100 ms";
  if (!(max_click_s > block_s)) return "max click length must be > one block";
  if (!(min_spacing_s >= 0)) return "min spacing must be >= 0 s";
  if (!(onset_fraction > 0 && onset_fraction < 1)) return "onset fraction must be in (0, 1)";
  if (!(min_floor > 0)) return "min floor must be > 0";
  return "";
}

ImpactDetector::ImpactDetector(ImpactDetectorConfig config, int sample_rate)
    : config_(config), rate_(sample_rate) {
  if (const std::string e = config_.Validate(); !e.empty())
    throw std::invalid_argument("impact detector: " + e);
  if (sample_rate < 4000 || sample_rate > 384000)
    throw std::invalid_argument("impact detector: sample rate must be 4-384 kHz, got " +
                                std::to_string(sample_rate) + " Hz");
  block_len_ = std::max(1, static_cast<int>(std::lround(config_.block_s * rate_)));
  const auto keep = static_cast<int64_t>(
      (config_.attack_s + config_.max_click_s + config_.rise_window_s + 0.01) * rate_ + 4 * block_len_);
  int64_t ring = 1;
  while (ring < keep) ring *= 2;
  history_.assign(static_cast<size_t>(ring), 0.0f);
  history_mask_ = ring - 1;
  const double fc = std::min(config_.highpass_hz, 0.45 * rate_);
  if (fc > 0) {  // RBJ cookbook high-pass, Q = 1/sqrt(2)
    const double w = 2 * std::numbers::pi * fc / rate_;
    const double alpha = std::sin(w) / std::numbers::sqrt2;
    const double cw = std::cos(w);
    const double a0 = 1 + alpha;
    b0_ = (1 + cw) / 2 / a0;
    b1_ = -(1 + cw) / a0;
    b2_ = (1 + cw) / 2 / a0;
    a1_ = -2 * cw / a0;
    a2_ = (1 - alpha) / a0;
  } else {
    b0_ = 1;
  }
}

int ImpactDetector::FloorBin(double energy) {
  const double db = Db(energy);
  return std::clamp(static_cast<int>(std::lround((db - kFloorLowDb) * kFloorBinsPerDb)), 0,
                    kFloorBins - 1);
}

double ImpactDetector::Floor() {
  if (block_energies_.empty()) return config_.min_floor * config_.min_floor;
  const auto k = static_cast<int64_t>(config_.floor_percentile * (block_energies_.size() - 1));
  int bin = 0;
  for (int64_t seen = 0; bin < kFloorBins; ++bin)
    if ((seen += floor_hist_[bin]) > k) break;
  const double db = kFloorLowDb + static_cast<double>(bin) / kFloorBinsPerDb;
  return std::max(std::pow(10.0, db / 10), config_.min_floor * config_.min_floor);
}

std::vector<AudioImpact> ImpactDetector::Push(double t0_s, const float* samples, size_t count) {
  std::vector<AudioImpact> out;
  if (!started_) {
    t_origin_s_ = t0_s;
    started_ = true;
  } else {
    // A gap in the stream re-bases the clock; the sample indexes stay contiguous.
    const double expected = t_origin_s_ + static_cast<double>(next_sample_) / rate_;
    if (std::abs(t0_s - expected) > 2.0 / rate_) t_origin_s_ = t0_s - static_cast<double>(next_sample_) / rate_;
  }
  for (size_t i = 0; i < count; ++i) {
    const double x = samples[i];
    const double y = b0_ * x + b1_ * x1_ + b2_ * x2_ - a1_ * y1_ - a2_ * y2_;
    x2_ = x1_, x1_ = x, y2_ = y1_, y1_ = y;
    history_[next_sample_ & history_mask_] = static_cast<float>(y);
    ++next_sample_;
    block_energy_acc_ += y * y;
    if (++block_fill_ == block_len_) ProcessBlock(&out);
  }
  return out;
}

void ImpactDetector::ProcessBlock(std::vector<AudioImpact>* out) {
  const double e = block_energy_acc_ / block_len_;
  block_energy_acc_ = 0;
  block_fill_ = 0;
  const int64_t block = block_index_++;
  const int64_t block_start = next_sample_ - block_len_;

  if (block % 8 == 0 || block_energies_.size() < 40) floor_rms_ = std::sqrt(Floor());
  const double floor_e = floor_rms_ * floor_rms_;

  if (in_click_ && Db(e / candidate_.peak_energy) >= config_.min_rise_db) {
    // Far louder than what triggered: a new click on top of a weaker sound; start over.
    candidate_.before_energy = candidate_.peak_energy;
    candidate_.early_energy = e;
    candidate_.block = block;
    candidate_.peak_energy = e;
    candidate_.peak_block = block;
  }
  if (in_click_) {
    if (e > candidate_.peak_energy) candidate_.peak_energy = e, candidate_.peak_block = block;
    const double age_s = static_cast<double>(block - candidate_.block) * block_len_ / rate_;
    if (age_s <= config_.attack_s) candidate_.early_energy = std::max(candidate_.early_energy, e);
    const double faded = candidate_.peak_energy * std::pow(10.0, -config_.decay_db / 10);
    const double since_peak_s =
        static_cast<double>(block - candidate_.peak_block) * block_len_ / rate_;
    if (e < faded || e < 2 * floor_e) {
      in_click_ = false;
      Decide(candidate_, out);
    } else if (since_peak_s > config_.max_click_s ||
               age_s > config_.attack_s + config_.max_click_s) {
      in_click_ = false;  // a sustained sound, not a click
    }
  } else if (block_energies_.size() >= 20) {
    // The loudest block of the rise window before it, skipping the last millisecond (a
    // click that starts late in a block puts part of itself there). A voice's pitch pulses
    // or a drum roll repeat within the window; an impact stands alone.
    const size_t n = std::min(block_energies_.size(),
                              static_cast<size_t>(std::ceil(config_.rise_window_s * rate_ / block_len_)));
    const size_t skip = std::min(n - 1, static_cast<size_t>(std::ceil(0.001 * rate_ / block_len_)));
    double before = 0;
    for (size_t k = block_energies_.size() - n; k < block_energies_.size() - skip; ++k)
      before = std::max(before, block_energies_[k]);
    const double snr = Db(e / floor_e);
    const double rise = Db(e / std::max(before, floor_e));
    const bool spaced =
        block_start - last_onset_sample_ >= config_.min_spacing_s * rate_;
    // Triggered at half the rise in dB; the click's attack must reach the full rise.
    if (snr >= config_.min_snr_db && rise >= config_.min_rise_db / 2 && spaced) {
      in_click_ = true;
      candidate_ = Candidate{};
      candidate_.block = block;
      candidate_.peak_energy = e;
      candidate_.peak_block = block;
      candidate_.early_energy = e;
      candidate_.before_energy = std::max(before, floor_e);
      candidate_.floor_energy = floor_e;
    }
  }
  block_energies_.push_back(e);
  ++floor_hist_[FloorBin(e)];
  const size_t window = static_cast<size_t>(config_.floor_window_s * rate_ / block_len_);
  while (block_energies_.size() > window) {
    --floor_hist_[FloorBin(block_energies_.front())];
    block_energies_.pop_front();
  }
}

bool ImpactDetector::Decide(const Candidate& c, std::vector<AudioImpact>* out) {
  const double rise_db = Db(c.early_energy / c.before_energy);
  if (rise_db < config_.min_rise_db) return false;
  // The click's peak: the largest |y| from a block before the trigger to a block after its
  // loudest block.
  const int64_t history_start = std::max<int64_t>(0, next_sample_ - static_cast<int64_t>(history_.size()));
  const int64_t trigger = c.block * block_len_;
  const int64_t from = std::max(history_start, trigger - block_len_);
  const int64_t to = std::min<int64_t>(next_sample_ - 1, (c.peak_block + 2) * block_len_);
  int64_t peak = from;
  double peak_abs = 0;
  for (int64_t s = from; s <= to; ++s) {
    const double a = std::abs(history_[s & history_mask_]);
    if (a > peak_abs) peak_abs = a, peak = s;
  }
  if (peak_abs <= 0) return false;
  // Onset: walk back from the peak; the earliest sample above the threshold, stopping after
  // half a millisecond below it (the click oscillates; the noise before it stays below).
  const double threshold = std::max(config_.onset_fraction * peak_abs, 4 * std::sqrt(c.floor_energy));
  const int64_t quiet_run = std::max<int64_t>(2, static_cast<int64_t>(0.0005 * rate_));
  int64_t onset = peak;
  for (int64_t s = peak, below = 0; s >= history_start && below < quiet_run; --s) {
    if (std::abs(history_[s & history_mask_]) >= threshold) onset = s, below = 0;
    else ++below;
  }
  // A click reaches its peak within a cycle or two of its onset; sound above the threshold
  // for longer before the peak is a ramp ahead of it (an encoder's pre-echo).
  if (peak - onset > static_cast<int64_t>(0.001 * rate_)) onset = SteepestRise(onset, peak, history_start);
  if (onset - last_onset_sample_ < config_.min_spacing_s * rate_) return false;
  last_onset_sample_ = onset;
  AudioImpact impact;
  impact.t_s = t_origin_s_ + static_cast<double>(onset) / rate_;
  impact.strength = peak_abs;
  impact.snr_db = Db(c.peak_energy / c.floor_energy);
  // Confidence: how far above the thresholds the click stood (10 dB margin each = certain).
  const double snr_margin = (impact.snr_db - config_.min_snr_db) / 10;
  const double rise_margin = (rise_db - config_.min_rise_db) / 10;
  impact.confidence = std::clamp(0.5 + 0.5 * std::min(snr_margin, rise_margin), 0.0, 1.0);
  out->push_back(impact);
  return true;
}

int64_t ImpactDetector::SteepestRise(int64_t from, int64_t to, int64_t history_start) const {
  // Where the energy of the next millisecond stands highest over the millisecond before: the
  // click itself, not the encoder's pre-echo ramp ahead of it (which rises ~3 dB per ms).
  // Millisecond windows average the ramp's noise out but place the step up to a window
  // early; the click's first cycle above half its amplitude within the window after it
  // is the onset.
  const int64_t w = std::max<int64_t>(2, static_cast<int64_t>(0.001 * rate_));
  if (from - w < history_start || to + w > next_sample_) return from;
  const auto y = [&](int64_t s) { return static_cast<double>(history_[s & history_mask_]); };
  double before = 0, after = 0;  // sums of y^2 over [s - w, s) and [s, s + w)
  for (int64_t s = from - w; s < from; ++s) before += y(s) * y(s);
  for (int64_t s = from; s < from + w; ++s) after += y(s) * y(s);
  const double tiny = 1e-30;
  int64_t step = from;
  double best_ratio = 0;
  for (int64_t s = from; s <= to; ++s) {
    if (const double ratio = (after + tiny) / (before + tiny); ratio > best_ratio) best_ratio = ratio, step = s;
    before += y(s) * y(s) - y(s - w) * y(s - w);
    after += y(s + w) * y(s + w) - y(s) * y(s);
  }
  double top = 0;
  for (int64_t s = step; s < step + w; ++s) top = std::max(top, std::abs(y(s)));
  for (int64_t s = step; s < step + w; ++s)
    if (std::abs(y(s)) >= 0.5 * top) return s;
  return step;
}

std::vector<AudioImpact> ImpactDetector::Finish() {
  std::vector<AudioImpact> out;
  if (in_click_) {
    in_click_ = false;
    Decide(candidate_, &out);
  }
  return out;
}

std::vector<AudioImpact> DetectImpacts(const std::vector<float>& samples, int sample_rate,
                                       double t0_s, const ImpactDetectorConfig& config) {
  ImpactDetector d(config, sample_rate);
  std::vector<AudioImpact> all = d.Push(t0_s, samples.data(), samples.size());
  for (const auto& i : d.Finish()) all.push_back(i);
  return all;
}

}  // namespace bouncefit
