#include "fit/node/fit_node.h"

#include "fit/fit_models.h"
#include "model/model_by_name.h"
#include "model/point_mass_model.h"

namespace bouncefit {

FitNode::FitNode(FitNodeConfig config, Callback on_update)
    : config_(std::move(config)), on_update_(std::move(on_update)) {
  ball_ = ResolveBallPreset(config_.ball, config_.diameter_m, config_.mass_kg);
  model_ = MakeBallModel(config_.model, ball_);
  quick_model_ = std::make_unique<PointMassModel>(ball_);
  ConfigureSessionForModel(*model_, ball_, &config_.session);
  auto session = std::make_unique<FitSession>(*model_, quick_model_.get(), config_.session);
  worker_ = std::make_unique<FitWorker>(std::move(session),
                                        [this](const FitUpdate& u) { Publish(u); });
}

FitNode::~FitNode() { Stop(); }

void FitNode::Attach(LcmBus* bus) {
  bus_ = bus;
  bus->Subscribe<bounce_peak_t>(config_.channels.bounce_peak,
                                [this](const bounce_peak_t& p) { OnPeak(p); });
}

void FitNode::Start() { worker_->Start(); }

void FitNode::OnPeak(const bounce_peak_t& peak) {
  {
    std::lock_guard<std::mutex> lock(peak_mutex_);
    last_peak_utime_ = peak.utime;
  }
  worker_->Submit(FromMessage(peak));
}

void FitNode::Finish() { worker_->Finish(); }
void FitNode::WaitIdle() { worker_->WaitIdle(); }
bool FitNode::WaitIdleFor(std::chrono::milliseconds timeout) {
  return worker_->WaitIdleFor(timeout);
}
void FitNode::Stop() {
  if (worker_) worker_->Stop();
}

int64_t FitNode::last_peak_utime() const {
  std::lock_guard<std::mutex> lock(peak_mutex_);
  return last_peak_utime_;
}

PeakInput FitNode::FromMessage(const bounce_peak_t& m) {
  PeakInput p;
  p.sequence = m.sequence;
  p.bounce = m.bounce;
  p.height_m = m.height_m;
  p.sigma_m = m.height_sigma_m > 0 ? m.height_sigma_m : 0;
  p.utime = m.utime;
  if (m.impact_before_utime != 0) p.impact_before_s = 1e-6 * static_cast<double>(m.impact_before_utime);
  if (m.apex_utime != 0) p.apex_s = 1e-6 * static_cast<double>(m.apex_utime);
  return p;
}

fit_update_t FitNode::ToMessage(const FitUpdate& u) {
  fit_update_t m{};
  m.utime = u.utime;
  m.sequence = u.sequence;
  m.after_bounce = u.after_bounce;
  m.final = u.final;
  m.model = u.model;
  m.method = u.method;
  m.num_coeffs = static_cast<int32_t>(u.coefficients.size());
  for (const auto& c : u.coefficients) {
    m.names.push_back(c.name);
    m.values.push_back(c.value);
    m.sigmas.push_back(c.sigma);
    m.identifiable.push_back(c.identifiable);
  }
  m.num_bounces = static_cast<int32_t>(u.recorded_m.size());
  m.recorded_m = u.recorded_m;
  m.simulated_m = u.simulated_m;
  m.simulated_m.resize(u.recorded_m.size(), 0.0);
  m.residual_m = u.residual_m;
  m.evaluations = u.evaluations;
  m.wall_time_s = u.wall_time_s;
  m.time_step_s = u.time_step_s;
  m.iterations = u.iterations;
  return m;
}

void FitNode::Publish(const FitUpdate& u) {
  const fit_update_t m = ToMessage(u);
  if (bus_) {
    std::lock_guard<std::mutex> lock(publish_mutex_);
    bus_->Publish(config_.channels.fit_update, m);
  }
  if (on_update_) on_update_(m, u);
}

}  // namespace bouncefit
