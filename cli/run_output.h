#pragma once
// Writes a run's output directory (docs/FORMATS.md) as messages arrive. Every line is
// flushed when written, so whatever happens later, what was already recorded stays on disk.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "model/ball_model.h"
#include "msgs/lcm_log_recorder.h"

namespace bouncefit::cli {

class RunOutput {
 public:
  // Creates dir (and parents). Throws std::runtime_error if it cannot be written.
  explicit RunOutput(const std::filesystem::path& dir);

  // The first frame's capture time: the zero of every t_s.
  void SetStreamStart(int64_t t0_utime) { t0_ = t0_utime; }
  int64_t stream_start() const { return t0_; }

  void OnBox(const ball_box_t& m);
  void OnCalibration(const calibration_t& m);
  void OnPeak(const bounce_peak_t& m);
  // published_utime: the stream time (latest frame) at which the update went out.
  void OnFit(const fit_update_t& m, int64_t published_utime);
  // Raw copy into session.lcm of a message this process published.
  template <class Msg>
  void Log(const std::string& channel, const Msg& m) {
    std::vector<uint8_t> buf(m.getEncodedSize());
    m.encode(buf.data(), 0, static_cast<int>(buf.size()));
    log_.Record(channel, buf.data(), buf.size(), m.utime);
  }

  LcmLogRecorder& log() { return log_; }

  // summary.json, written atomically (temp file + rename).
  void WriteSummary(const nlohmann::json& summary);
  const std::filesystem::path& dir() const { return dir_; }
  // Closes session.lcm; returns messages written and dropped.
  std::pair<int64_t, int64_t> CloseLog();

 private:
  std::filesystem::path dir_;
  int64_t t0_ = 0;
  std::ofstream track_;
  std::ofstream peaks_;
  std::ofstream fits_;
  LcmLogRecorder log_;
};

// simulated.csv in `dir` (docs/FORMATS.md): a simulated drop's trajectory, its release at
// t_release_s on the stream clock, beside the recorded one for the report's Fig. 7.
void WriteSimulatedCsv(const std::filesystem::path& dir, double t_release_s,
                       const std::vector<TrajectorySample>& trajectory);

}  // namespace bouncefit::cli
