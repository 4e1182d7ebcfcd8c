#pragma once
// `run`: the capture, detect and fit nodes hosted in one process. They talk over an
// in-process bus (memq://) exactly as they do over the network when each runs as a process
// of its own; every message is also published on the outside bus (so `watch`, lcm-spy and
// lcm-logger see the session). One output directory holds what each node owns.
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pipeline/capture_stage.h"
#include "pipeline/detect_stage.h"
#include "pipeline/exit_status.h"
#include "pipeline/fit_stage.h"

namespace bouncefit {

class LcmBus;

struct PipelineConfig {
  CaptureStageConfig capture;
  DetectStageConfig detect;
  std::optional<FitStageConfig> fit;  // none: track and detect only
  std::string lcm_url;                // the outside bus ("memq://": none)
  std::filesystem::path out_dir;
  bool overwrite = false;             // clear an earlier run's files in out_dir first
};

struct PipelineOutcome {
  ExitStatus status = kExitAnswer;
  std::string why;            // one line: why not an answer (empty for an answer)
  int rows = 0;               // rows of peaks.csv
  int rebounds = 0;           // of them, rebounds
  stream_t stream;            // STREAM end: frames, found, ...
  std::optional<FitUpdate> final_fit;
};

class Pipeline {
 public:
  using NoticeFn = std::function<void(const std::string&)>;

  // Claims the output directory (refused if it holds an earlier run and !overwrite), opens
  // the source and both buses; throws like the stages do.
  Pipeline(PipelineConfig config, NoticeFn notice);
  ~Pipeline();

  // The in-process bus: subscribe to it to follow the session (the console does).
  LcmBus& bus() { return *bus_; }
  CaptureStage& capture() { return *capture_; }
  const BallPreset& ball() const { return config_.detect.ball; }
  int final_budget() const { return fit_ ? fit_->final_budget() : 0; }

  // Runs the stream to its end (or until *stop), then the final fit. `progress` is called
  // after every frame, `fit_progress` while the final fit runs (simulations, budget).
  // A flag the measurement contradicts: throws std::invalid_argument, this run's files removed.
  PipelineOutcome Run(const std::atomic<bool>* stop, const std::function<void()>& progress,
                      const std::function<void(int, int)>& fit_progress);

 private:
  void Open();  // the buses and the nodes

  PipelineConfig config_;
  NoticeFn notice_;
  std::unique_ptr<LcmBus> outside_;
  std::unique_ptr<LcmBus> bus_;
  std::unique_ptr<FitStage> fit_;
  std::unique_ptr<DetectStage> detect_;
  std::unique_ptr<CaptureStage> capture_;
};

}  // namespace bouncefit
