#pragma once
// Impacts heard in a sound track: onsets of short broadband clicks, timed to the sample
// A core with no I/O: push mono samples with their times, get impacts
// back once each is certain (a few ms after its onset).
//
// How: a high-pass (default 2 kHz) removes hum and most of speech's energy; a filter bank
// splits the rest into half-octave bands (detect/click_filter_bank.h). Each band's energy
// over 1 ms windows, every 0.5 ms, is compared with that band's own noise floor (a
// percentile of its last 0.4 s, so a click does not raise it) and with the loudest it was
// in the 20 ms before (a click stands alone; pitch pulses and rattles repeat). An onset is
// scored by how many bands rise above both and by how much (each band's rise in dB,
// capped, summed): a ball's click is broadband and sudden, so a soft one rises a little in
// most bands at once, while a voice or a whistle rises in a few and room noise in none
// for long. A score of half the threshold starts a candidate. At its loudest, within
// attack_s of the start, the bands must stand the full score over what they were
// max_rise_s to rise_window_s before (a click, or a click behind the ramp of quantisation
// noise a phone's AAC encoder spreads up to a frame, ~23 ms, ahead of a loud transient;
// not a hissed consonant, whose first milliseconds rise steeply but which keeps rising).
// It must fade within max_click_s of its peak and stay down for fade_hold_s (a click and
// its ringing tail, not a note, a vowel or a consonant's plateau).
// Its onset is the first sample, going back from the click's peak, where the high-passed
// signal is still above a fraction of the peak's amplitude (a ramp's pre-echo stays below
// it), or, for a click whose first cycles are within the noise, where its energy starts to
// accumulate. Strength is the peak amplitude; confidence grows with how far the score
// stood above the threshold.
#include <cstdint>
#include <string>
#include <vector>

#include "detect/click_filter_bank.h"
#include "detect/sliding_percentile.h"

namespace bouncefit {

struct AudioImpact {
  double t_s = 0;          // onset, seconds (the clock of the samples pushed)
  double strength = 0;     // peak amplitude of the high-passed click, full scale 1
  double snr_db = 0;       // peak energy over the noise floor, bands averaged, dB
  double confidence = 0;   // 0..1
};

struct ImpactDetectorConfig {
  double highpass_hz = 2000;     // clicks are broadband; hum, voices and most music are not
  double top_hz = 16000;         // the bands end here (or at 0.45 of the sample rate)
  double bands_per_octave = 2;
  double block_s = 0.0005;       // hop between energy windows
  double window_s = 0.001;       // each band's energy window
  double floor_window_s = 0.4;   // each band's noise floor: a percentile of this long a past
  double floor_percentile = 0.5;
  double band_rise_db = 6;       // a band rises when this far over its floor and over its
  double rise_window_s = 0.02;   //  loudest window of the preceding rise_window_s
  double band_cap_db = 15;       // one band's share of the score at most
  double min_score_db = 30;      // summed rises of the bands to be a click (half starts one)
  double min_band_fraction = 0.5;  // ... with at least this fraction of the bands rising
  double attack_s = 0.025;       // the click is loudest within this of the start
  double max_rise_s = 0.006;     // its step: the loudest over what was this long before
  double max_click_s = 0.03;     // the click's energy falls below decay_db of its peak within
  double decay_db = 12;          //  this long after the peak (sustained sounds are not impacts)
  double fade_hold_s = 0.005;    // ... and stays down, on average, this long
  double min_spacing_s = 0.012;  // two impacts closer than this are one
  double onset_fraction = 0.2;   // onset: first sample above this fraction of the peak
  double min_floor = 1e-5;       // floor never below this RMS over the band (digital silence)

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

  double noise_floor_rms() const;  // the high-passed sound's, all bands
  int sample_rate() const { return rate_; }
  int bands() const { return bank_.bands(); }

 private:
  struct Candidate {
    int64_t start_block = 0;     // where its score first reached half the threshold
    int64_t peak_block = 0;      // its loudest block, and that level (energy over floor,
    double peak_level = 0;       //  bands averaged)
    double score = 0;            // the step there (dB summed over bands) and its rising bands
    int rising = 0;
    double base_level = 0;       // what that step rose from (over floor, bands averaged)
    double floor_energy = 0;     // the high-passed sound's floor when it started
    int fading_blocks = 0;       // blocks since it faded (0: not yet)
    double fading_sum = 0;       // their levels, summed
    double faded_level = 0;      // the level it faded below
  };

  void ProcessBlock(std::vector<AudioImpact>* out);
  // Summed capped rises (dB) of energies over references, and how many bands rose.
  double Score(const double* energy, const double* reference, int* rising) const;
  // A new loudest block of the candidate: its step over what came before.
  void Peak(int64_t block, double level, Candidate* c) const;
  bool Decide(const Candidate& c, std::vector<AudioImpact>* out);
  // The sample in [from, to] where the energy rises most steeply (the onset behind a ramp).
  int64_t SteepestRise(int64_t from, int64_t to, int64_t history_start) const;

  ImpactDetectorConfig config_;
  int rate_;
  int block_len_;
  int window_blocks_;          // blocks per energy window
  int rise_blocks_;            // windows in the rise window
  int skip_blocks_;            // latest windows left out of it (they may hold the click)
  ClickFilterBank bank_;
  int bands_;
  int min_bands_;

  double t_origin_s_ = 0;      // time of absolute sample 0
  bool started_ = false;
  int64_t next_sample_ = 0;    // absolute index of the next sample pushed
  // Recent filtered samples, a ring: absolute sample s is at s & history_mask_, for the last
  // history_.size() samples (no allocation per sample or per push).
  std::vector<float> history_;
  int64_t history_mask_ = 0;

  std::vector<double> block_samples_;  // this block's high-passed samples
  std::vector<double> block_acc_;   // per band, this block's sum of squares
  double wide_acc_ = 0;             // the high-passed signal's
  int block_fill_ = 0;
  int64_t block_index_ = 0;
  std::vector<double> block_energy_;  // per band, the last window_blocks_ blocks' energies, a ring
  std::vector<double> window_;        // per band, the last rise_blocks_ windows' energies, a ring
  std::vector<SlidingPercentile> floors_;  // per band
  SlidingPercentile wide_floor_;
  int hold_blocks_;
  std::vector<double> min_band_floor_;
  // Scratch per block (no allocation per block).
  std::vector<double> energy_, floor_, reference_;

  bool in_click_ = false;
  Candidate candidate_;
  int64_t last_onset_sample_ = -1000000000;
};

// Runs a detector over a whole track. Throws like ImpactDetector.
std::vector<AudioImpact> DetectImpacts(const std::vector<float>& samples, int sample_rate,
                                       double t0_s, const ImpactDetectorConfig& config = {});

}  // namespace bouncefit
