#pragma once
// The fit node: BOUNCE_PEAK (bounce_peak_t) in, FIT_UPDATE (fit_update_t) out.
//
// A thin adapter around FitWorker: OnPeak() only hands the peak to the worker thread, so
// the LCM loop (or the `run` pipeline calling it in-process) never waits for a fit.
// Updates are published on the bus when attached to one, and passed to the callback.
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "fit/fit_session.h"
#include "fit/fit_worker.h"
#include "model/ball_model.h"
#include "model/ball_preset.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"

namespace bouncefit {

struct FitNodeConfig {
  std::string ball = "pingpong";
  double mass_kg = 0;       // > 0 overrides the preset
  double diameter_m = 0;    // > 0 overrides the preset
  std::string model = "bullet-softbody";  // or "point-mass"
  FitSessionConfig session;
  Channels channels;
};

class FitNode {
 public:
  // Called on the worker thread with every update (point-mass, per-bounce, final).
  using Callback = std::function<void(const fit_update_t&, const FitUpdate&)>;

  // Builds the models; throws std::invalid_argument for an unknown ball or model.
  explicit FitNode(FitNodeConfig config, Callback on_update = {});
  ~FitNode();
  FitNode(const FitNode&) = delete;
  FitNode& operator=(const FitNode&) = delete;

  // Subscribes to the peaks on `bus` and publishes updates there (call before Start()).
  void Attach(LcmBus* bus);
  void Start();
  void OnPeak(const bounce_peak_t& peak);  // never blocks on a fit
  void Finish();                           // final fit of the current drop
  void WaitIdle();
  bool WaitIdleFor(std::chrono::milliseconds timeout);  // true if idle
  int simulations() const { return worker_->simulations(); }
  int final_budget() const { return worker_->final_budget(); }
  void Stop();

  const BallPreset& ball() const { return ball_; }
  const BallModel& model() const { return *model_; }
  FitWorker::Stats stats() const { return worker_->stats(); }
  int64_t last_peak_utime() const;

  static fit_update_t ToMessage(const FitUpdate& update);
  static PeakInput FromMessage(const bounce_peak_t& peak);

 private:
  void Publish(const FitUpdate& update);

  FitNodeConfig config_;
  Callback on_update_;
  BallPreset ball_;
  std::unique_ptr<BallModel> model_;
  std::unique_ptr<BallModel> quick_model_;
  std::unique_ptr<FitWorker> worker_;
  LcmBus* bus_ = nullptr;
  std::mutex publish_mutex_;
  mutable std::mutex peak_mutex_;
  int64_t last_peak_utime_ = 0;
};

}  // namespace bouncefit
