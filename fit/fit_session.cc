#include "fit/fit_session.h"

#include <cmath>

#include "fit/answer_gate.h"
#include "fit/update_report.h"

namespace bouncefit {

namespace {

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The settings, checked before anything reads them.
FitSessionConfig Validated(FitSessionConfig config, const BallModel& model) {
  ValidateFitSessionConfig(config, model);
  return config;
}

}  // namespace

FitSession::FitSession(const BallModel& model, const BallModel* quick_model, FitSessionConfig config)
    : model_(model),
      quick_model_(quick_model),
      config_(Validated(std::move(config), model)),
      drop_(config_.min_bounce_height_m, config_.default_sigma_m),
      problems_(model_, config_, drop_, kept_),
      live_(model_, quick_model_, config_, drop_, problems_),
      final_(model_, quick_model_, config_, drop_, kept_, problems_, live_.warm_start(), live_.order()) {}

void FitSession::Reset(int sequence) {
  sequence_ = sequence;
  drop_.Clear();
}

void FitSession::KeepDropAndReset(int sequence) {
  if (CanFit()) kept_.push_back(drop_.Keep());
  Reset(sequence);
}

bool FitSession::AddPeak(const PeakInput& p) {
  if (p.sequence != sequence_) return false;
  if (!std::isfinite(p.height_m) || p.bounce < 0) return true;  // nothing usable
  last_utime_ = p.utime;
  drop_.Add(p.bounce, {p.height_m, p.sigma_m, p.impact_before_s, p.apex_s});
  return true;
}

FitUpdate FitSession::Report(const FitProblem& problem, const SearchResult& r, bool final,
                             const std::vector<std::vector<double>>& jacobian, int extra_evals,
                             std::chrono::steady_clock::time_point t0, const BallModel& model) const {
  UpdateContext c;
  c.utime = last_utime_;
  c.sequence = sequence_;
  c.start_bounce = drop_.start_bounce();
  c.after_bounce = drop_.start_bounce() + static_cast<int>(drop_.fitted_heights().size());
  c.drop_height_m = drop_.drop_height_m();
  c.flight_clock_ratio = drop_.flight_clock_ratio();
  c.measurement_sigma_m = drop_.MeasurementSigma();
  // Every coefficient the session may fit is reported (the quick model's: all of them).
  const bool fitted = &model == &model_;
  c.reported = fitted ? FreeCoefficients(model_, config_) : model.Coefficients();
  if (fitted) {
    c.time_step_s = config_.time_step_s;
    c.iterations = config_.iterations;
  }
  return ReportUpdate(c, problem, r, final, jacobian, extra_evals, Seconds(t0), model);
}

FitUpdate FitSession::QuickUpdate() {
  const auto t0 = std::chrono::steady_clock::now();
  const LiveStepResult s = live_.Quick();
  return Report(s.problem, s.result, false, s.result.jacobian, 0, t0, *quick_model_);
}

FitUpdate FitSession::Update(const CancelToken* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  const LiveStepResult s = live_.Update(cancel, &simulations_);
  return Report(s.problem, s.result, false, s.result.jacobian, 0, t0, model_);
}

FitUpdate FitSession::FinalUpdate(const CancelToken* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  const FinalSearchResult s = final_.Search(cancel, &simulations_);
  // Live updates go on from the answer, the most sensitive coefficients first.
  live_.TakeFinal(s.result, s.jacobian, s.problem.free);
  FitUpdate u = Report(s.problem, s.result, true, s.jacobian, s.jacobian_evaluations, t0, model_);
  final_.Check(s, cancel, &simulations_, &u);
  u.no_answer = WhyNoAnswer(u, !s.result.failure.empty() && !s.result.cancelled, config_.answer_floor_m,
                            config_.answer_fraction);
  u.wall_time_s = Seconds(t0);
  return u;
}

}  // namespace bouncefit
