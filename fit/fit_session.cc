#include "fit/fit_session.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <future>
#include <set>
#include <thread>
#include <stdexcept>

#include <Eigen/Dense>

#include "fit/drop_ensemble.h"
#include "fit/fit_session_helpers.h"
#include "fit/least_squares_search.h"
#include "fit/live_step.h"
#include "fit/nlopt_search.h"
#include "fit/paper_search.h"
#include "fit/restitution_fit.h"

namespace bouncefit {

using namespace fit_session_detail;

double TimeStepOf(const CoefficientValues& values) {
  for (const auto& [name, v] : values)
    if (name.find("time_step") != std::string::npos) return v;
  return 0;
}

int IterationsOf(const CoefficientValues& values) {
  for (const auto& [name, v] : values)
    if (name.find("iterations") != std::string::npos) return static_cast<int>(std::lround(v));
  return 0;
}

FitSession::FitSession(const BallModel& model, const BallModel* quick_model,
                       FitSessionConfig config)
    : model_(model), quick_model_(quick_model), config_(std::move(config)) {
  if (config_.live_method != "gauss-newton" && config_.live_method != "search")
    throw std::invalid_argument("unknown live method '" + config_.live_method +
                                "' (known: gauss-newton, search)");
  if (config_.objective != "segments" && config_.objective != "drop")
    throw std::invalid_argument("unknown objective '" + config_.objective +
                                "' (known: segments, drop)");
  if (config_.impact != "boost" && config_.impact != "restitution")
    throw std::invalid_argument("unknown impact '" + config_.impact +
                                "' (known: boost, restitution)");
  if (config_.method != "nlopt" && config_.method != "paper")
    throw std::invalid_argument("unknown fit method '" + config_.method +
                                "' (known: nlopt, paper)");
  const auto specs = model_.Coefficients();
  for (const auto& name : config_.free) {
    bool found = false;
    for (const auto& s : specs) found = found || s.name == name;
    if (!found)
      throw std::invalid_argument("model '" + model_.name() + "' has no coefficient '" + name +
                                  "'");
  }
  for (const auto& s : specs) current_[s.name] = s.default_value;
  for (const auto& [name, v] : config_.start) {
    bool found = false;
    for (const auto& s : specs) found = found || s.name == name;
    if (found) current_[name] = v;
  }
  final_start_ = current_;
  if (quick_model_)
    for (const auto& s : quick_model_->Coefficients()) quick_current_[s.name] = s.default_value;
  const auto free = FreeSpecs();
  for (const auto& name : config_.live_priority)
    for (const auto& s : free)
      if (s.name == name && !Contains(live_order_, name)) live_order_.push_back(name);
  for (const auto& s : free)
    if (!Contains(live_order_, s.name)) live_order_.push_back(s.name);
  initial_live_order_ = live_order_;
}

void FitSession::Reset(int sequence) {
  sequence_ = sequence;
  apexes_.clear();
  start_bounce_ = 0;
  drop_height_m_ = 0;
  heights_.clear();
  sigmas_.clear();
  impacts_before_.clear();
}

void FitSession::KeepDropAndReset(int sequence) {
  if (CanFit()) kept_.push_back(ThisDrop());
  Reset(sequence);
}

FitSession::KeptDrop FitSession::ThisDrop() const {
  const std::vector<double> heights = FittedHeights();
  std::vector<double> sigmas{apexes_.at(start_bounce_).sigma_m};
  sigmas.insert(sigmas.end(), sigmas_.begin(), sigmas_.begin() + static_cast<long>(heights.size()));
  return {drop_height_m_, heights, FittedFlights(), sigmas, start_bounce_};
}

bool FitSession::AddPeak(const PeakInput& p) {
  if (p.sequence != sequence_) return false;
  if (!std::isfinite(p.height_m) || p.bounce < 0) return true;  // nothing usable
  last_utime_ = p.utime;
  apexes_[p.bounce] = {p.height_m, p.sigma_m, p.impact_before_s, p.apex_s};
  ChooseStart();
  return true;
}

void FitSession::ChooseStart() {
  // Runs of consecutive bounces, each apex high enough to fit and none higher than the one
  // before it (a ball picked up and dropped again, or a lock on something else, is not a
  // rebound); bounce 0 (the release) starts a run at any height. The start is the release
  // when it begins a run with a rebound after it, else the first apex of the longest run
  // (the earliest of equal ones).
  const double min_h = config_.min_bounce_height_m;
  auto usable = [&](int b) {
    auto it = apexes_.find(b);
    return it != apexes_.end() && (b == 0 || it->second.height_m >= min_h);
  };
  auto follows = [&](int b) {  // apex b is a rebound of apex b - 1
    return b > 0 && usable(b) && usable(b - 1) &&
           apexes_.at(b).height_m <= 1.05 * apexes_.at(b - 1).height_m + 0.002;
  };
  int best_start = -1, best_len = 0;
  for (const auto& [b, a] : apexes_) {
    if (!usable(b) || follows(b)) continue;  // not a run's first apex
    int len = 0;
    while (follows(b + len + 1)) ++len;
    const bool release = b == 0 && len > 0;
    if (release) {
      best_start = 0, best_len = len;
      break;
    }
    if (best_start < 0 || len > best_len) best_start = b, best_len = len;
  }
  heights_.clear();
  sigmas_.clear();
  impacts_before_.clear();
  if (best_start < 0) {
    start_bounce_ = 0;
    drop_height_m_ = 0;
    return;
  }
  start_bounce_ = best_start;
  drop_height_m_ = apexes_.at(best_start).height_m;
  for (int b = best_start + 1; b <= best_start + best_len; ++b) {
    const Apex& a = apexes_.at(b);
    heights_.push_back(a.height_m);
    sigmas_.push_back(a.sigma_m);
    impacts_before_.push_back(a.impact_before_s);
  }
  // The flight of the last arc needs the next bounce's impact_before, when that bounce was
  // seen (below the minimum or not) and is a rebound of it.
  auto next = apexes_.find(best_start + best_len + 1);
  if (next != apexes_.end() && next->second.height_m <= 1.05 * apexes_.at(best_start + best_len).height_m + 0.002)
    impacts_before_.push_back(next->second.impact_before_s);
}

std::vector<double> FitSession::FittedHeights() const {
  std::vector<double> r;
  for (double h : heights_) {
    if (!std::isfinite(h) || h < config_.min_bounce_height_m) break;
    r.push_back(h);
  }
  return r;
}

std::vector<double> FitSession::FittedFlights() const {
  const std::vector<double> h = FittedHeights();
  const size_t k = h.size();
  std::vector<double> f(k, std::numeric_limits<double>::quiet_NaN());
  for (size_t i = 0; i < k && i + 1 < impacts_before_.size(); ++i)
    f[i] = impacts_before_[i + 1] - impacts_before_[i];  // NaN when either is
  // Flights on another clock than the heights' (a slow-motion file's impacts on its slowed
  // timeline, heights from the real one): the flight a height gives, 2 sqrt(2 h / g) drag
  // aside, against the recorded one. Far off by their median: the heights alone are fitted.
  std::vector<double> ratios;
  for (size_t i = 0; i < k; ++i)
    if (std::isfinite(f[i]) && h[i] > 0) ratios.push_back(f[i] / (2 * std::sqrt(2 * h[i] / 9.81)));
  flight_clock_ratio_ = std::nan("");
  if (!ratios.empty()) {
    std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
    const double median = ratios[ratios.size() / 2];
    if (median < 0.8 || median > 1.2) {
      flight_clock_ratio_ = median;
      std::fill(f.begin(), f.end(), std::numeric_limits<double>::quiet_NaN());
    }
  }
  return f;
}

double FitSession::StartFall() const {
  if (impacts_before_.empty() || !apexes_.count(start_bounce_)) return std::nan("");
  const double fall = impacts_before_[0] - apexes_.at(start_bounce_).apex_s;  // NaN when either is
  return fall > 0 ? fall : std::nan("");
}

double FitSession::MeasurementSigma() const {
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < FittedHeights().size(); ++i)
    if (sigmas_[i] > 0) sum += sigmas_[i] * sigmas_[i], ++n;
  return n ? std::sqrt(sum / n) : config_.default_sigma_m;
}

std::vector<CoefficientSpec> FitSession::FreeSpecs() const {
  std::vector<CoefficientSpec> free;
  for (const auto& s : model_.Coefficients()) {
    if (!config_.free.empty()) {
      if (Contains(config_.free, s.name)) free.push_back(s);
      continue;
    }
    if (!(s.upper > s.lower)) continue;
    bool never = s.name == "radius";
    for (const auto& pattern : config_.never_fit)
      never = never || s.name.find(pattern) != std::string::npos;
    if (!never) free.push_back(s);
  }
  std::stable_sort(free.begin(), free.end(), [](const auto& a, const auto& b) {
    return PaperPriority(a.name) < PaperPriority(b.name);
  });
  return free;
}

FitProblem FitSession::MakeProblem(const std::vector<CoefficientSpec>& free,
                                   const CoefficientValues& at, bool live) const {
  FitProblem p;
  p.model = &model_;
  p.free = free;
  p.fixed = at;
  p.recorded_m = FittedHeights();
  p.recorded_flight_s = FittedFlights();
  p.flight_weight_mps = config_.impact == "restitution" ? config_.flight_weight_mps : 0;
  // The first fall on the heights' clock: the impacts' divided by the flights' ratio to it when
  // FittedFlights found them on another (a slow-motion file).
  const double heights_s_per_stream_s = std::isfinite(flight_clock_ratio_) ? 1 / flight_clock_ratio_ : 1;
  p.start_fall_s = StartFall() * heights_s_per_stream_s;
  p.start_fall_sigma_s = config_.time_sigma_s * heights_s_per_stream_s;
  p.segments = config_.objective == "segments";
  for (const auto& [name, step] : config_.grid) p.grid[name] = step;
  if (p.recorded_m.empty()) throw std::logic_error("no bounce to fit yet");
  const int k = static_cast<int>(p.recorded_m.size());
  p.simulation.drop_height_m = drop_height_m_;
  const double t_k = FreeFallApexTime(drop_height_m_, p.recorded_m, k);
  p.simulation.duration_s =
      live ? config_.live_duration_margin * t_k + 0.08 : config_.duration_margin * t_k + 0.2;
  const double lowest = *std::min_element(p.recorded_m.begin(), p.recorded_m.end());
  p.simulation.min_bounce_height_m = 0.5 * std::min(config_.min_bounce_height_m, lowest);
  // No simulation runs past the last recorded bounce (a third of a drop's steps or more).
  p.simulation.max_bounces = k;
  // The final fits take the kept drops too (the live ones follow the drop in progress).
  if (!live)
    for (const auto& d : kept_) {
      p.recorded_m.insert(p.recorded_m.end(), d.heights_m.begin(), d.heights_m.end());
      p.recorded_flight_s.insert(p.recorded_flight_s.end(), d.flights_s.begin(), d.flights_s.end());
      p.other_drops.push_back({d.drop_height_m, static_cast<int>(d.heights_m.size())});
      for (double h : d.heights_m)
        p.simulation.min_bounce_height_m = std::min(p.simulation.min_bounce_height_m, 0.5 * h);
    }
  return p;
}

FitUpdate FitSession::Finish(const FitProblem& problem, const SearchResult& r, bool final,
                             const std::vector<std::vector<double>>& jacobian, int extra_evals,
                             double wall_s, const BallModel& model) {
  FitUpdate u;
  u.utime = last_utime_;
  u.sequence = sequence_;
  u.start_bounce = start_bounce_;
  // This drop's last bounce fitted (a joint fit's recorded_m holds the other drops' too).
  u.after_bounce = start_bounce_ + static_cast<int>(FittedHeights().size());
  u.final = final;
  u.cancelled = r.cancelled;
  u.model = model.name();
  u.method = r.method;
  u.values = r.values;
  u.drop_height_m = drop_height_m_;
  u.recorded_m = problem.recorded_m;
  u.simulated_m = r.simulated_m;
  for (const auto& d : problem.other_drops) {
    u.other_drop_heights_m.push_back(d.drop_height_m);
    u.other_drop_bounces.push_back(d.bounces);
  }
  u.residual_m = RmsResidual(problem.recorded_m, r.simulated_m);
  if (problem.segments) {
    u.segment_simulated_m = r.simulated_m;
    u.segment_residual_m = u.residual_m;
  }
  u.evaluations = r.evaluations + extra_evals;
  u.wall_time_s = wall_s;
  u.time_step_s = TimeStepOf(r.values);
  u.iterations = IterationsOf(r.values);
  if (&model == &model_) {
    if (u.time_step_s == 0) u.time_step_s = config_.time_step_s;
    if (u.iterations == 0) u.iterations = config_.iterations;
  }
  u.no_effect = r.inactive;
  if (std::isfinite(flight_clock_ratio_))
    AddWarning(&u, fmt::format("the flight times between impacts are {:.2g}x what the heights give (the impacts "
                               "on another clock?): the heights are fitted, not the flights; the first fall is "
                               "read on the flights' clock",
                               flight_clock_ratio_));

  std::vector<CoefficientEstimate> est;
  if (!jacobian.empty())
    est = EstimateUncertainty(problem.free, r.values, jacobian, u.residual_m, MeasurementSigma());
  // The covariance of the identifiable ones, in their own units (what `predict` propagates:
  // e0 and its slope are strongly anti-correlated, their sigmas alone overstate the spread).
  if (!jacobian.empty()) {
    std::vector<size_t> cols;
    for (size_t j = 0; j < est.size() && j < problem.free.size(); ++j)
      if (est[j].identifiable) cols.push_back(j);
    const size_t k = jacobian.size(), n = cols.size();
    if (n > 0 && k >= n) {
      Eigen::MatrixXd J(k, n);
      for (size_t i = 0; i < k; ++i)
        for (size_t c = 0; c < n; ++c)
          J(i, c) = jacobian[i][cols[c]] / (problem.free[cols[c]].upper - problem.free[cols[c]].lower);
      double sigma = MeasurementSigma();
      sigma = std::max(sigma, k > n ? u.residual_m * std::sqrt(double(k) / double(k - n)) : u.residual_m);
      const Eigen::MatrixXd JtJ = J.transpose() * J;
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(JtJ, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Eigen::VectorXd sv = svd.singularValues();
      Eigen::MatrixXd inv = Eigen::MatrixXd::Zero(n, n);
      for (Eigen::Index d = 0; d < sv.size(); ++d)
        if (sv(d) > 1e-12 * sv(0)) inv += svd.matrixV().col(d) * svd.matrixU().col(d).transpose() / sv(d);
      const Eigen::MatrixXd cov = sigma * sigma * inv;
      for (size_t c = 0; c < n; ++c) {
        u.covariance_names.push_back(problem.free[cols[c]].name);
        u.covariance.emplace_back();
        for (size_t d = 0; d < n; ++d) u.covariance.back().push_back(cov(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(d)));
      }
    }
  }
  // Every coefficient the session may fit is reported; those not searched in this update
  // keep their value, without an uncertainty.
  const auto all = (&model == &model_) ? FreeSpecs() : model.Coefficients();
  for (const auto& s : all) {
    CoefficientEstimate e;
    auto it = std::find_if(est.begin(), est.end(), [&](const auto& x) { return x.name == s.name; });
    if (it != est.end()) {
      e = *it;
    } else {
      e.name = s.name;
      e.unit = s.unit;
      auto v = r.values.find(s.name);
      e.value = v != r.values.end() ? v->second : s.default_value;
      e.sigma = std::numeric_limits<double>::quiet_NaN();
      e.note = jacobian.empty() ? "no sensitivity computed" : "held fixed in this update";
      bool searched = false;
      for (const auto& f : problem.free) searched = searched || f.name == s.name;
      if (searched) e.note = "no sensitivity computed";
    }
    if (Contains(r.inactive, s.name)) e.note = "no effect on the heights";
    if (!e.identifiable) u.unidentified.push_back(e.name);
    if (e.note == "no effect on the heights" && !Contains(u.no_effect, e.name))
      u.no_effect.push_back(e.name);
    u.coefficients.push_back(e);
  }
  return u;
}

FitUpdate FitSession::QuickUpdate() {
  if (!quick_model_) throw std::logic_error("no quick model for this session");
  const auto t0 = std::chrono::steady_clock::now();
  // Never more coefficients than the bounces can tell apart: restitution alone from one
  // or two bounces, then its speed dependence, then drag (the model's order).
  const auto all = quick_model_->Coefficients();
  const int k = static_cast<int>(FittedHeights().size());
  const int count = std::clamp(k - 1, 1, static_cast<int>(all.size()));
  FitProblem p = MakeProblem({all.begin(), all.begin() + count}, quick_current_);
  p.model = quick_model_;
  p.segments = false;  // the point mass is not chaotic: its free drop is the best estimate
  SearchOptions o;
  o.max_evaluations = config_.max_evaluations_quick;
  o.threads = 1;  // each point-mass run takes a few milliseconds
  // Matching the heights far below their uncertainty buys nothing.
  o.target_rms_m = 0.01 * MeasurementSigma();
  const SearchResult r = LeastSquaresSearch(p, quick_current_, o);
  // The next quick fit starts from here; missing heights make no sense to carry over.
  for (const auto& s : p.free) quick_current_[s.name] = r.values.at(s.name);
  quick_fitted_ = r.evaluations > 0 && r.failure.empty();
  return Finish(p, r, false, r.jacobian, 0, Seconds(t0), *quick_model_);
}

FitUpdate FitSession::Update(const CancelToken* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  const int k = static_cast<int>(FittedHeights().size());
  // The most sensitive coefficients (at most one per bounce): what k heights can tell.
  const std::vector<CoefficientSpec> live =
      FirstSpecs(live_order_, std::max(1, std::min(config_.live_coefficients, k)));
  const bool fast = config_.live_method == "gauss-newton";
  // Under the restitution law the soft ball starts each live update on the point mass's
  // latest curve (QuickUpdate, milliseconds), not on the preset's: a carpet's e 0.5 is
  // far from a ping-pong preset's 0.92 for one Gauss-Newton step.
  if (UsesRestitutionLaw() && quick_current_.count("restitution") && quick_fitted_)
    current_ = WithRestitutionLaw(current_, quick_current_.at("restitution"),
                                  quick_current_.at("restitution_per_mps"),
                                  quick_current_.at("drag_coefficient"));
  FitProblem p = MakeProblem(live, current_, fast);
  SearchOptions o;
  o.max_evaluations = config_.max_evaluations_per_bounce;
  o.threads = config_.threads;
  o.simulations = &simulations_;
  o.cancel = cancel;
  if (config_.target_rms_fraction > 0) o.target_rms_m = config_.target_rms_fraction * drop_height_m_;
  // A warm start that already matches the heights to their uncertainty needs no second
  // round: the update goes out after one round of simulations.
  if (fast) o.target_rms_m = std::max(o.target_rms_m, MeasurementSigma());
  SearchResult r = fast                         ? LiveStep(p, current_, o)
                   : config_.method == "paper" ? PaperSearch(p, current_, o)
                                               : NloptSearch(p, current_, o);
  if (r.evaluations > 0) current_ = r.values;
  // Coefficients with no effect go to the back of the live order.
  for (const auto& name : r.inactive) {
    auto it = std::find(live_order_.begin(), live_order_.end(), name);
    if (it != live_order_.end()) {
      live_order_.erase(it);
      live_order_.push_back(name);
    }
  }
  return Finish(p, r, false, r.jacobian, 0, Seconds(t0), model_);
}

std::vector<CoefficientSpec> FitSession::FirstSpecs(const std::vector<std::string>& order,
                                                    int n) const {
  const auto specs = FreeSpecs();
  std::vector<CoefficientSpec> out;
  for (const auto& name : order) {
    if (static_cast<int>(out.size()) >= n) break;
    for (const auto& s : specs)
      if (s.name == name) out.push_back(s);
  }
  return out;
}

}  // namespace bouncefit
