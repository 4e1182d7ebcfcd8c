#pragma once
// The detect node: BALL_BOX and the impacts heard (IMPACT) in; CALIBRATION, BOUNCE_PEAK
// (each bounce once, then its revisions), the impacts seen (IMPACT) and DROP out. It owns
// the sound's fusion with the picture, the drop-end refit, and peaks.csv, impacts.csv,
// calibration.json and summary.json.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/drop_t.hpp"
#include "bouncefit/impact_t.hpp"
#include "bouncefit/stream_t.hpp"
#include "detect/capture_clock_detector.h"
#include "model/ball_preset.h"
#include "msgs/channels.h"

namespace bouncefit {

class ClockReport;
class LcmBus;
class SoundFusion;

struct DetectStageConfig {
  BallPreset ball;             // its diameter checks the scale; its drag times the flights
  double px_per_m = 0;         // > 0: the user's scale
  double drop_height_m = 0;    // > 0: the scale from the release height
  double time_scale = 0;       // > 0: real s per stream s (0: the clock decides)
  bool keep_frame_times = false;  // never re-time dropped pictures (only say so)
  bool force = false;          // keep a scale or clock flag the measurement contradicts
  int frame_width_px = 0, frame_height_px = 0;  // when no STREAM says so (an older log)
  bool announce_stream = true;  // say what the stream is when it starts (its host may say it already)
  Channels channels;
  std::filesystem::path out_dir;  // empty: nothing written
};

class DetectStage {
 public:
  using NoticeFn = std::function<void(const std::string&)>;

  // Subscribes to its inputs on `bus` and publishes there. Throws std::invalid_argument
  // for an invalid configuration.
  DetectStage(DetectStageConfig config, LcmBus& bus, NoticeFn notice = {});
  ~DetectStage();

  void OnStream(const stream_t& m);
  void OnBox(const ball_box_t& m);
  void OnImpact(const impact_t& m);
  // The stream ended without its STREAM end (the capture node gone): close what is open.
  void FinishWithoutEnd();

  bool done() const { return done_; }            // the stream ended and every file is written
  const std::string& fatal() const { return fatal_; }  // a flag the measurement contradicts
  int rows() const { return rows_; }             // rows of peaks.csv (once done)
  int rebounds() const { return rebounds_; }     // of them, rebounds (bounce 1 and later)
  int boxes() const { return boxes_; }
  bool stream_failed() const { return !end_.failure.empty(); }
  const stream_t& stream_end() const { return end_; }
  int64_t last_box_wall_us() const { return last_box_wall_us_; }

 private:
  void StartStream(int64_t t0_utime);
  // A fresh detector for a stream whose times went backwards (a replay started again); the
  // events that close the old one.
  std::vector<DetectorEvent> RestartDetector();
  // Every drop ended so far, across restarts.
  std::vector<SequenceSummary> Summaries() const;
  void Handle(const std::vector<DetectorEvent>& events);
  void OnCalibration(const Calibration& c);
  void CheckFlags(const Calibration& c);
  void EmitPeak(bounce_peak_t m);
  void PublishHeardPeaks();
  void Finish();
  void WriteSummary(const std::vector<bounce_peak_t>& rows);

  DetectStageConfig config_;
  LcmBus& bus_;
  NoticeFn notice_;
  BounceDetectorConfig detector_config_;
  FrameRetimingConfig retiming_config_;
  std::unique_ptr<CaptureClockDetector> detector_;
  std::vector<SequenceSummary> earlier_summaries_;  // of the detectors before a restart
  double detect_s_ = 0;                             // time spent in the detector
  int64_t last_box_utime_ = 0;
  bool have_box_ = false;
  std::unique_ptr<SoundFusion> sound_;
  std::unique_ptr<ClockReport> clock_;
  stream_t start_{}, end_{};
  bool started_ = false, have_end_ = false, done_ = false, retiming_said_ = false,
       slow_motion_said_ = false, sound_off_said_ = false;
  int64_t t0_ = 0, now_ = 0, release_utime_ = 0;
  std::vector<bounce_peak_t> emitted_;  // revision 0 of every bounce, in order
  std::optional<calibration_t> calibration_;
  std::unique_ptr<std::ofstream> peaks_csv_;  // the live rows until the final ones replace them
  std::string fatal_;
  int rows_ = 0, rebounds_ = 0, boxes_ = 0;
  int64_t last_box_wall_us_ = 0;
};

}  // namespace bouncefit
