#include "fit/live_updates.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fit/least_squares_search.h"
#include "fit/live_step.h"
#include "fit/nlopt_search.h"
#include "fit/paper_search.h"
#include "fit/restitution_fit.h"

namespace bouncefit {

LiveUpdates::LiveUpdates(const BallModel& model, const BallModel* quick_model, const FitSessionConfig& config,
                         const RecordedDrop& drop, const DropProblems& problems)
    : model_(model), quick_model_(quick_model), config_(config), drop_(drop), problems_(problems) {
  const auto specs = model_.Coefficients();
  for (const auto& s : specs) current_[s.name] = s.default_value;
  for (const auto& [name, v] : config_.start) {
    bool found = false;
    for (const auto& s : specs) found = found || s.name == name;
    if (found) current_[name] = v;
  }
  if (quick_model_)
    for (const auto& s : quick_model_->Coefficients()) quick_current_[s.name] = s.default_value;
  order_ = LiveOrder(FreeCoefficients(model_, config_), config_);
}

LiveStepResult LiveUpdates::Quick() {
  if (!quick_model_) throw std::logic_error("no quick model for this session");
  // Never more coefficients than the bounces can tell apart: restitution alone from one
  // or two bounces, then its speed dependence, then drag (the model's order).
  const auto all = quick_model_->Coefficients();
  const int k = static_cast<int>(drop_.fitted_heights().size());
  const int count = std::clamp(k - 1, 1, static_cast<int>(all.size()));
  FitProblem p = problems_.Make({all.begin(), all.begin() + count}, quick_current_);
  p.model = quick_model_;
  p.segments = false;  // the point mass is not chaotic: its free drop is the best estimate
  SearchOptions o;
  o.max_evaluations = config_.max_evaluations_quick;
  o.threads = 1;  // each point-mass run takes a few milliseconds
  // Matching the heights far below their uncertainty buys nothing.
  o.target_rms_m = 0.01 * drop_.MeasurementSigma();
  SearchResult r = LeastSquaresSearch(p, quick_current_, o);
  // The next quick fit starts from here; missing heights make no sense to carry over.
  for (const auto& s : p.free) quick_current_[s.name] = r.values.at(s.name);
  quick_fitted_ = r.evaluations > 0 && r.failure.empty();
  return {std::move(p), std::move(r)};
}

LiveStepResult LiveUpdates::Update(const CancelToken* cancel, std::atomic<int>* simulations) {
  const int k = static_cast<int>(drop_.fitted_heights().size());
  // The most sensitive coefficients (at most one per bounce): what k heights can tell.
  const std::vector<CoefficientSpec> live = FirstCoefficients(
      FreeCoefficients(model_, config_), order_, std::max(1, std::min(config_.live_coefficients, k)));
  const bool fast = config_.live_method == "gauss-newton";
  // Under the restitution law the soft ball starts each live update on the point mass's
  // latest curve (Quick, milliseconds), not on the preset's: a carpet's e 0.5 is far from a
  // ping-pong preset's 0.92 for one Gauss-Newton step.
  if (UsesRestitutionLaw(config_, model_, quick_model_) && quick_current_.count("restitution") && quick_fitted_)
    current_ = WithRestitutionLaw(current_, quick_current_.at("restitution"),
                                  quick_current_.at("restitution_per_mps"),
                                  quick_current_.at("drag_coefficient"));
  FitProblem p = problems_.Make(live, current_, fast);
  SearchOptions o;
  o.max_evaluations = config_.max_evaluations_per_bounce;
  o.threads = config_.threads;
  o.simulations = simulations;
  o.cancel = cancel;
  if (config_.target_rms_fraction > 0) o.target_rms_m = config_.target_rms_fraction * drop_.drop_height_m();
  // A warm start that already matches the heights to their uncertainty needs no second
  // round: the update goes out after one round of simulations.
  if (fast) o.target_rms_m = std::max(o.target_rms_m, drop_.MeasurementSigma());
  SearchResult r = fast                         ? LiveStep(p, current_, o)
                   : config_.method == "paper" ? PaperSearch(p, current_, o)
                                               : NloptSearch(p, current_, o);
  if (r.evaluations > 0) current_ = r.values;
  // Coefficients with no effect go to the back of the live order.
  for (const auto& name : r.inactive) {
    auto it = std::find(order_.begin(), order_.end(), name);
    if (it != order_.end()) {
      order_.erase(it);
      order_.push_back(name);
    }
  }
  return {std::move(p), std::move(r)};
}

void LiveUpdates::TakeFinal(const SearchResult& r, const std::vector<std::vector<double>>& jacobian,
                            const std::vector<CoefficientSpec>& free) {
  if (r.evaluations > 0) current_ = r.values;
  if (jacobian.empty()) return;
  std::vector<std::pair<double, std::string>> effect;
  for (size_t j = 0; j < free.size(); ++j) {
    double e = 0;
    for (const auto& row : jacobian) e = std::max(e, std::abs(row[j]));
    effect.emplace_back(-e, free[j].name);
  }
  std::stable_sort(effect.begin(), effect.end());
  order_.clear();
  for (const auto& [e, name] : effect) order_.push_back(name);
}

}  // namespace bouncefit
