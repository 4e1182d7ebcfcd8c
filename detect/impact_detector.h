#pragma once
// Impacts heard in a sound track: onsets of short broadband clicks, timed to the sample
// A core with no I/O: push mono samples with their times, get impacts
// back once each is certain (a few ms after its onset).
//
// How: a high-pass (default 2 kHz) removes hum and most of speech's and music's energy; the
// short-term energy of 0.5 ms blocks is compared with an adaptive noise floor (a low
// percentile of the last 0.4 s of blocks, so a click does not raise it). A block far above
// the floor that also rises far above everything in the 20 ms before it starts a click; it
// must reach min_rise_db over that within attack_s (a click, or a click behind the ramp of
// quantisation noise a phone's AAC encoder spreads up to a frame, ~23 ms, ahead of a loud
// transient), and then fade within max_click_s of its peak (a click, not a note or a vowel).
// Its onset is the first sample, going back from the click's peak, where the filtered
// signal is still above a fraction of the peak's amplitude (a ramp's pre-echo stays below
// it). Strength is the peak amplitude; confidence grows with how far the click stands above
// the floor and how sharply it rose.
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace bouncefit {

struct AudioImpact {
  double t_s = 0;          // onset, seconds (the clock of the samples pushed)
  double strength = 0;     // peak amplitude of the high-passed click, full scale 1
  double snr_db = 0;       // peak block energy over the noise floor, dB
  double confidence = 0;   // 0..1
};

struct ImpactDetectorConfig {
  double highpass_hz = 2000;     // clicks are broadband; hum, voices and most music are not
  double block_s = 0.0005;       // energy block length
  double floor_window_s = 0.4;   // noise floor: percentile of the blocks of this long a past
  double floor_percentile = 0.3;
  double min_snr_db = 16;        // block energy over the floor to start a click
  double min_rise_db = 10;       // ... and (within attack_s) over the loudest block of the
  double rise_window_s = 0.02;   //  preceding rise_window_s (a click stands alone; pitch
  double attack_s = 0.025;       //  pulses repeat)
  double max_click_s = 0.03;     // the click's energy falls below decay_db of its peak within
  double decay_db = 12;          //  this long after the peak (sustained sounds are not impacts)
  double min_spacing_s = 0.012;  // two impacts closer than this are one
  double onset_fraction = 0.2;   // onset: first sample above this fraction of the peak
  double min_floor = 1e-5;       // floor never below this RMS (digital silence)

  // Empty when valid, else a one-line reason.
  std::string Validate() const;
};

class ImpactDetector {
 public:
  // Throws std::invalid_argument with a one-line reason for a bad config or sample rate.
  ImpactDetector(ImpactDetectorConfig config, int sample_rate);

  // Samples heard from t0_s on (t0_s + i / rate); consecutive calls continue the stream
  // (t0_s of a later call only sets its time if there was a gap). Returns the impacts that
  // became certain.
  std::vector<AudioImpact> Push(double t0_s, const float* samples, size_t count);
  // End of stream: the impacts still pending.
  std::vector<AudioImpact> Finish();

  double noise_floor_rms() const { return floor_rms_; }
  int sample_rate() const { return rate_; }

 private:
  struct Candidate {
    int64_t block = 0;           // block index where it triggered
    double peak_energy = 0;
    int64_t peak_block = 0;
    double floor_energy = 0;
    double early_energy = 0;     // loudest block of its first attack_s
    double before_energy = 0;    // loudest block of the rise window before it
    int64_t peak_sample = 0;     // absolute sample index of the largest |x|
    double peak_abs = 0;
  };

  void ProcessBlock(std::vector<AudioImpact>* out);
  bool Decide(const Candidate& c, std::vector<AudioImpact>* out);
  double Floor();
  // The sample in [from, to] where the energy rises most steeply (the onset behind a ramp).
  int64_t SteepestRise(int64_t from, int64_t to, int64_t history_start) const;
  static int FloorBin(double energy);

  ImpactDetectorConfig config_;
  int rate_;
  int block_len_;
  // High-pass: a second-order Butterworth biquad.
  double b0_ = 0, b1_ = 0, b2_ = 0, a1_ = 0, a2_ = 0;
  double x1_ = 0, x2_ = 0, y1_ = 0, y2_ = 0;

  double t_origin_s_ = 0;      // time of absolute sample 0
  bool started_ = false;
  int64_t next_sample_ = 0;    // absolute index of the next sample pushed
  // Recent filtered samples, a ring: absolute sample s is at s & history_mask_, for the last
  // history_.size() samples (no allocation per sample or per push).
  std::vector<float> history_;
  int64_t history_mask_ = 0;

  double block_energy_acc_ = 0;
  int block_fill_ = 0;
  int64_t block_index_ = 0;
  std::deque<double> block_energies_;  // recent blocks (floor window)
  // The floor window's block energies as a histogram of 0.1 dB bins from -120 to +20 dB
  // full scale: its percentile costs a scan of the bins, not a selection of the blocks.
  static constexpr double kFloorLowDb = -120, kFloorBinsPerDb = 10;
  static constexpr int kFloorBins = 1400;
  std::vector<int> floor_hist_ = std::vector<int>(kFloorBins, 0);
  double floor_rms_ = 0;

  bool in_click_ = false;
  Candidate candidate_;
  int64_t last_onset_sample_ = -1000000000;
};

// Runs a detector over a whole track. Throws like ImpactDetector.
std::vector<AudioImpact> DetectImpacts(const std::vector<float>& samples, int sample_rate,
                                       double t0_s, const ImpactDetectorConfig& config = {});

}  // namespace bouncefit
