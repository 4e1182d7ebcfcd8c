#pragma once
// The sound side of `bouncefit run`: decodes the clip's sound track paced with the video,
// publishes each heard impact (IMPACT, impact_t) as the video reaches it, forwards seen
// impacts, and at the end fuses both (detect/impact_fusion.h) into impacts.csv and the
// flight-time heights of peaks.csv.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/impact_t.hpp"
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

  bool enabled() const { return source_ != nullptr; }
  std::string Describe() const { return description_; }

  // Decodes and listens up to video time t_s (s since the first frame); returns the heard
  // impacts that became certain, as messages (utime on the frames' clock, from t0_utime).
  std::vector<impact_t> AdvanceTo(double t_s, int64_t t0_utime);
  // A seen impact as a message.
  impact_t Seen(double t_s, int64_t t0_utime);
  // End: decodes the rest, fuses with the seen impacts (video clock, s).
  const FusionResult& Finish(const std::vector<double>& seen_t_s, double video_end_s);

  // Writes impacts.csv; rewrites peaks.csv with the heard flight heights (docs/FORMATS.md).
  void WriteImpactsCsv(const std::filesystem::path& dir) const;
  void RewritePeaksCsv(const std::filesystem::path& dir, const std::vector<bounce_peak_t>& peaks,
                       int64_t t0_utime) const;
  nlohmann::json Summary() const;
  double cpu_s() const { return cpu_s_; }

 private:
  std::unique_ptr<AudioFileSource> source_;
  std::unique_ptr<ImpactDetector> detector_;
  std::string description_;
  BallPreset ball_;
  std::vector<AudioImpact> heard_;
  FusionResult fused_;
  bool finished_ = false, ended_ = false;
  int next_index_ = 0;
  double decoded_to_s_ = -1e9;
  double cpu_s_ = 0;  // decoding + detecting, CPU seconds of the calling thread
};

}  // namespace bouncefit::cli
