#include "detect/impact_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {
namespace {

double Db(double ratio) { return 10 * std::log10(std::max(ratio, 1e-30)); }

}  // namespace

std::string ImpactDetectorConfig::Validate() const {
  if (!(highpass_hz >= 0)) return "high-pass must be >= 0 Hz";
  if (!(top_hz > highpass_hz)) return "the bands' top must be above the high-pass";
  if (!(bands_per_octave > 0 && bands_per_octave <= 12)) return "bands per octave must be in (0, 12]";
  if (!(block_s > 0 && block_s <= 0.01)) return "block must be in (0, 10] ms";
  if (!(window_s >= block_s && window_s <= 8 * block_s)) return "window must be 1 to 8 blocks";
  if (!(floor_window_s >= 20 * block_s)) return "noise-floor window must hold >= 20 blocks";
  if (!(floor_percentile > 0 && floor_percentile < 1)) return "floor percentile must be in (0, 1)";
  if (!(band_rise_db > 0) || !(band_cap_db >= band_rise_db) || !(min_score_db > 0) || !(decay_db > 0))
    return "dB thresholds must be > 0 (and the cap >= the band rise)";
  if (!(min_band_fraction > 0 && min_band_fraction <= 1)) return "band fraction must be in (0, 1]";
  if (!(rise_window_s >= 4 * block_s)) return "rise window must be >= four blocks";
  if (!(attack_s >= block_s && attack_s <= 0.1)) return "attack must be one block to 100 ms";
  if (!(max_click_s > block_s)) return "max click length must be > one block";
  if (!(max_rise_s >= block_s && max_rise_s < rise_window_s))
    return "max rise must be one block to the rise window";
  if (!(fade_hold_s >= block_s && fade_hold_s <= 0.05)) return "fade hold must be one block to 50 ms";
  if (!(min_spacing_s >= 0)) return "min spacing must be >= 0 s";
  if (!(onset_fraction > 0 && onset_fraction < 1)) return "onset fraction must be in (0, 1)";
  if (!(min_floor > 0)) return "min floor must be > 0";
  return "";
}

namespace {

const ImpactDetectorConfig& Checked(const ImpactDetectorConfig& c, int rate) {
  if (const std::string e = c.Validate(); !e.empty())
    throw std::invalid_argument("impact detector: " + e);
  if (rate < 4000 || rate > 384000)
    throw std::invalid_argument("impact detector: sample rate must be 4-384 kHz, got " +
                                std::to_string(rate) + " Hz");
  return c;
}

int Blocks(double s, int block_len, int rate) {
  return std::max(1, static_cast<int>(std::lround(s * rate / block_len)));
}

}  // namespace

ImpactDetector::ImpactDetector(ImpactDetectorConfig config, int sample_rate)
    : config_(Checked(config, sample_rate)),
      rate_(sample_rate),
      block_len_(std::max(1, static_cast<int>(std::lround(config_.block_s * rate_)))),
      window_blocks_(Blocks(config_.window_s, block_len_, rate_)),
      rise_blocks_(Blocks(config_.rise_window_s, block_len_, rate_)),
      skip_blocks_(std::max(1, static_cast<int>(std::ceil(0.001 * rate_ / block_len_)))),
      bank_(config_.highpass_hz, config_.top_hz, config_.bands_per_octave, rate_),
      bands_(bank_.bands()),
      min_bands_(std::max(1, static_cast<int>(std::ceil(config_.min_band_fraction * bands_ - 1e-9)))),
      wide_floor_(Blocks(config_.floor_window_s, block_len_, rate_), config_.floor_percentile),
      hold_blocks_(Blocks(config_.fade_hold_s, block_len_, rate_)) {
  const auto keep = static_cast<int64_t>(
      (config_.attack_s + config_.max_click_s + config_.rise_window_s + 0.01) * rate_ + 4 * block_len_);
  int64_t ring = 1;
  while (ring < keep) ring *= 2;
  history_.assign(static_cast<size_t>(ring), 0.0f);
  history_mask_ = ring - 1;
  rise_blocks_ = std::max(rise_blocks_, skip_blocks_ + 2);
  const int floor_blocks = Blocks(config_.floor_window_s, block_len_, rate_);
  for (int b = 0; b < bands_; ++b) {
    floors_.emplace_back(floor_blocks, config_.floor_percentile);
    // Digital silence: min_floor's RMS spread evenly over the band's share of the spectrum.
    const double share = (bank_.band_high_hz(b) - bank_.band_low_hz(b)) / (0.5 * rate_);
    min_band_floor_.push_back(config_.min_floor * config_.min_floor * share);
  }
  block_acc_.assign(bands_, 0.0);
  block_samples_.assign(block_len_, 0.0);
  block_energy_.assign(static_cast<size_t>(bands_) * window_blocks_, 0.0);
  window_.assign(static_cast<size_t>(bands_) * rise_blocks_, 0.0);
  energy_.assign(bands_, 0.0);
  floor_.assign(bands_, 0.0);
  reference_.assign(bands_, 0.0);
}

double ImpactDetector::noise_floor_rms() const {
  return std::sqrt(std::max(wide_floor_.Value(), config_.min_floor * config_.min_floor));
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
    const double y = bank_.HighPass(samples[i]);
    history_[next_sample_ & history_mask_] = static_cast<float>(y);
    ++next_sample_;
    wide_acc_ += y * y;
    block_samples_[block_fill_] = y;
    if (++block_fill_ == block_len_) {
      bank_.AddBandEnergies(block_samples_.data(), block_len_, block_acc_.data());
      ProcessBlock(&out);
    }
  }
  return out;
}

double ImpactDetector::Score(const double* energy, const double* reference, int* rising) const {
  double score = 0;
  *rising = 0;
  for (int b = 0; b < bands_; ++b) {
    const double rise = Db(energy[b] / reference[b]);
    if (rise >= config_.band_rise_db) ++*rising;
    score += std::clamp(rise, 0.0, config_.band_cap_db);
  }
  return score;
}

void ImpactDetector::ProcessBlock(std::vector<AudioImpact>* out) {
  const int64_t block = block_index_++;
  const int64_t block_start = next_sample_ - block_len_;
  const int slot = static_cast<int>(block % window_blocks_);
  const int rise_slot = static_cast<int>(block % rise_blocks_);
  const double wide = wide_acc_ / block_len_;
  wide_acc_ = 0;
  block_fill_ = 0;

  // Each band's energy over the window ending with this block, and its floor.
  double level = 0;  // energy over floor, bands averaged
  int loud = 0;      // bands band_rise_db over their floor
  const double rise_ratio = std::pow(10.0, config_.band_rise_db / 10);
  for (int b = 0; b < bands_; ++b) {
    double* ring = &block_energy_[static_cast<size_t>(b) * window_blocks_];
    ring[slot] = block_acc_[b] / block_len_;
    block_acc_[b] = 0;
    double sum = 0;
    for (int k = 0; k < window_blocks_; ++k) sum += ring[k];
    energy_[b] = sum / window_blocks_;
    floor_[b] = std::max(floors_[b].size() > 0 ? floors_[b].Value() : 0.0, min_band_floor_[b]);
    level += energy_[b] / floor_[b];
    loud += energy_[b] >= rise_ratio * floor_[b];
  }
  level /= bands_;

  // The onset's score, when enough bands stand over their floors to start a click: each
  // band's rise over the louder of its floor and its loudest window in the rise window
  // (leaving out the latest, which a click starting late in a block reaches).
  int rising = 0;
  double score = 0;
  if (!in_click_ && 2 * loud >= min_bands_ && block >= std::max(20, rise_blocks_)) {
    for (int b = 0; b < bands_; ++b) {
      // The ring holds windows block - rise_blocks_ .. block - 1 from rise_slot on.
      const double* past = &window_[static_cast<size_t>(b) * rise_blocks_];
      double before = floor_[b];
      for (int i = 0, at = rise_slot; i < rise_blocks_ - skip_blocks_; ++i) {
        before = std::max(before, past[at]);
        at = at + 1 == rise_blocks_ ? 0 : at + 1;
      }
      reference_[b] = before;
    }
    score = Score(energy_.data(), reference_.data(), &rising);
  }
  const double block_s = static_cast<double>(block_len_) / rate_;
  if (in_click_) {
    Candidate& c = candidate_;
    if (level > c.peak_level) Peak(block, level, &c), c.fading_blocks = 0;
    const double faded =
        std::max({c.peak_level * std::pow(10.0, -config_.decay_db / 10), 2.0, 2 * c.base_level});
    if (c.fading_blocks > 0) {
      // Faded: it must stay down for fade_hold_s (a click's tail; a hissed consonant
      // that dipped after its first step comes back up).
      c.fading_sum += level;
      if (++c.fading_blocks > hold_blocks_) {
        in_click_ = false;
        if (c.fading_sum / hold_blocks_ < c.faded_level) Decide(c, out);
      }
    } else if (level < faded) {
      // Half the decay under its peak on average: a ringing tail fluctuates about where it
      // faded to; a plateau that dipped returns near the peak.
      c.fading_blocks = 1, c.fading_sum = 0;
      c.faded_level = std::max(faded, c.peak_level * std::pow(10.0, -config_.decay_db / 20));
    } else if (static_cast<double>(block - c.peak_block) * block_s > config_.max_click_s) {
      in_click_ = false;  // a sustained sound, not a click
    }
  } else if (score >= config_.min_score_db / 2 && 2 * rising >= min_bands_ &&
             block_start - last_onset_sample_ >= config_.min_spacing_s * rate_) {
    // Started at half the score; Decide asks for the full score at its loudest.
    in_click_ = true;
    candidate_.start_block = block;
    candidate_.fading_blocks = 0;
    candidate_.floor_energy = std::max(wide_floor_.Value(), config_.min_floor * config_.min_floor);
    Peak(block, level, &candidate_);
  }
  for (int b = 0; b < bands_; ++b) {
    window_[static_cast<size_t>(b) * rise_blocks_ + rise_slot] = energy_[b];
    floors_[b].Push(energy_[b]);
  }
  wide_floor_.Push(wide);
}

void ImpactDetector::Peak(int64_t block, double level, Candidate* c) const {
  // The click's step: each band's energy now (or a window ago: a click starting late in a
  // window fills the next) over the loudest it was from rise_window_s to max_rise_s before
  // (an encoder's pre-echo ramp, rising to just under the click, is far lower that long
  // before it; a hissed consonant's plateau is not).
  const int step =
      std::min(rise_blocks_ - 1, std::max(skip_blocks_, Blocks(config_.max_rise_s, block_len_, rate_)));
  double score = 0, base = 0;
  int rising = 0;
  for (int b = 0; b < bands_; ++b) {
    const double* past = &window_[static_cast<size_t>(b) * rise_blocks_];
    const double top = std::max(energy_[b], block >= 1 ? past[(block - 1) % rise_blocks_] : 0.0);
    double before = floor_[b];
    for (int64_t j = block - rise_blocks_; j <= block - step; ++j)
      if (j >= 0) before = std::max(before, past[j % rise_blocks_]);
    const double rise = Db(top / before);
    if (rise >= config_.band_rise_db) ++rising;
    score += std::clamp(rise, 0.0, config_.band_cap_db);
    base += before / floor_[b];
  }
  c->peak_block = block;
  c->peak_level = level;
  c->score = score;
  c->rising = rising;
  c->base_level = base / bands_;
}

bool ImpactDetector::Decide(const Candidate& c, std::vector<AudioImpact>* out) {
  // A click: at its loudest, soon after its start, a step of the full score in enough bands.
  if (c.score < config_.min_score_db || c.rising < min_bands_ ||
      static_cast<double>(c.peak_block - c.start_block) * block_len_ / rate_ > config_.attack_s)
    return false;
  // The click's peak: the largest |y| from a window before the step to a block after its
  // loudest block.
  const int64_t history_start = std::max<int64_t>(0, next_sample_ - static_cast<int64_t>(history_.size()));
  const int64_t start = c.start_block * block_len_;
  const int64_t from = std::max(history_start, start - window_blocks_ * block_len_);
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
  if (peak - onset > static_cast<int64_t>(0.001 * rate_)) {
    onset = SteepestRise(onset, peak, history_start);
  } else if (threshold > config_.onset_fraction * peak_abs) {
    // A soft click, its first cycles within the noise: where the energy above the noise
    // starts to accumulate (a Page-Hinkley change point: the minimum of the running sum
    // of y^2 less four times the noise's power, from 2 ms before the peak).
    const double drift = 4 * c.floor_energy;
    double sum = 0, lowest = 0;
    const int64_t back = std::max(history_start, peak - static_cast<int64_t>(0.002 * rate_));
    for (int64_t s = back; s <= peak; ++s) {
      const double y = history_[s & history_mask_];
      if (sum < lowest || s == back) lowest = sum, onset = s;
      sum += y * y - drift;
    }
  }
  if (onset - last_onset_sample_ < config_.min_spacing_s * rate_) return false;
  last_onset_sample_ = onset;
  AudioImpact impact;
  impact.t_s = t_origin_s_ + static_cast<double>(onset) / rate_;
  impact.strength = peak_abs;
  impact.snr_db = Db(c.peak_level);
  // Confidence: how far above the threshold the score stood (twice the threshold = certain).
  impact.confidence = std::clamp(0.5 + 0.5 * (c.score - config_.min_score_db) / config_.min_score_db, 0.0, 1.0);
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
