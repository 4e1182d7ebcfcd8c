#pragma once
// The sound side of `bouncefit run`: decodes the clip's sound track paced with the video (or
// listens to a live microphone beside the camera), publishes each heard impact (IMPACT,
// impact_t) as the video reaches it, forwards seen impacts, and at the end fuses both
// (detect/impact_fusion.h) into impacts.csv and the flight-time heights of peaks.csv.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/impact_t.hpp"
#include "capture/microphone_reader.h"
#include "detect/impact_detector.h"
#include "detect/impact_fusion.h"
#include "model/ball_preset.h"
#include "replay/audio_file_source.h"

namespace bouncefit::cli {

class RunSound {
 public:
  // Opens the clip's sound (no clip, or a clip without sound: enabled() false).
  // Throws std::runtime_error only for an unreadable file.
  RunSound(const std::string& clip, const BallPreset& ball);
  // A live microphone (frames stamped on CLOCK_MONOTONIC, as V4L2 cameras stamp them).
  // Throws std::runtime_error with a one-line reason when it cannot be opened.
  RunSound(const AlsaMicrophoneConfig& mic, const BallPreset& ball);
  ~RunSound();

  bool enabled() const { return source_ != nullptr || mic_ != nullptr; }
  // The picture's frame period, s (a seen impact is timed to about a frame).
  void set_frame_period_s(double s) { frame_period_s_ = s; }
  std::string Describe() const { return description_; }

  // Decodes and listens up to video time t_s (s since the first frame; a microphone: all it
  // heard so far); returns the heard impacts that became certain, as messages (utime on the
  // frames' clock, t0_utime the first frame's).
  std::vector<impact_t> AdvanceTo(double t_s, int64_t t0_utime);
  // A microphone: stops listening; the impacts still pending.
  std::vector<impact_t> EndLive(int64_t t0_utime);
  // A seen impact as a message. `key` is the detector's (sequence, impact index): an impact
  // the detector revises (one it saw twice, merged) replaces the earlier one and goes out
  // again with the same message index.
  impact_t Seen(double t_s, int64_t t0_utime, std::pair<int, int> key);
  // The published peaks whose arc was heard from end to end (both impacts, the sound
  // checked against the picture so far), each once: BOUNCE_PEAK again for the same bounce,
  // with the flight-time height as height_m and flight_height_m (utime: now).
  std::vector<bounce_peak_t> HeardPeaks(const std::vector<bounce_peak_t>& published,
                                        int64_t t0_utime, int64_t now_utime);
  // Whether HeardPeaks has sent this bounce again with its flight-time height.
  bool WasHeard(int sequence, int bounce) const { return heard_peaks_.count({sequence, bounce}) > 0; }
  // End: decodes the rest, fuses with the seen impacts (video clock, s).
  const FusionResult& Finish(const std::vector<double>& seen_t_s, double video_end_s);

  // Writes impacts.csv; rewrites peaks.csv with the heard flight heights (docs/FORMATS.md).
  void WriteImpactsCsv(const std::filesystem::path& dir) const;
  // Writes waveform.csv: the sound's peak |amplitude| per 5 ms (nothing without sound).
  void WriteWaveformCsv(const std::filesystem::path& dir) const;
  // `after_refit[i]`: peaks[i]'s height refitted when its drop ended and its flight-time height
  // from the drop's impacts (NaN where none; the vector may be empty).
  struct AfterRefit {
    double refit_m = std::numeric_limits<double>::quiet_NaN();
    double flight_m = std::numeric_limits<double>::quiet_NaN();
  };
  void RewritePeaksCsv(const std::filesystem::path& dir, const std::vector<bounce_peak_t>& peaks,
                       const std::vector<AfterRefit>& after_refit, int64_t t0_utime) const;
  nlohmann::json Summary() const;
  double cpu_s() const { return cpu_s_; }

 private:
  void Listen(const AudioChunk& chunk, double shift_s, int64_t t0_utime, std::vector<impact_t>* out);
  void Publish(size_t from, int64_t t0_utime, std::vector<impact_t>* out);
  void Envelope(const AudioChunk& chunk, double t0_s);
  ImpactFusionConfig FusionConfig() const;

  static constexpr double kWaveBinS = 0.005;  // waveform.csv's window

  std::unique_ptr<AudioFileSource> source_;
  std::unique_ptr<MicrophoneReader> mic_;
  std::unique_ptr<ImpactDetector> detector_;
  std::string description_;
  BallPreset ball_;
  std::vector<AudioImpact> heard_;
  std::vector<double> seen_t_s_;               // seen impacts so far (video clock)
  std::map<std::pair<int, int>, std::pair<size_t, int>> seen_keys_;  // key -> (in seen_t_s_, message index)
  std::set<std::pair<int, int>> heard_peaks_;  // (sequence, bounce) already re-sent
  FusionResult fused_;
  bool finished_ = false, ended_ = false;
  int next_index_ = 0;
  double decoded_to_s_ = -1e9;
  double first_sample_t_s_ = NAN;  // video clock
  std::vector<float> wave_peak_;    // per kWaveBinS window from wave_first_bin_
  int64_t wave_first_bin_ = 0;
  double frame_period_s_ = 0;
  double cpu_s_ = 0;  // decoding + detecting, CPU seconds of the calling thread
};

}  // namespace bouncefit::cli
