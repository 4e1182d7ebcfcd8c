#include "fit/fit_session.h"

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
#include "fit/least_squares_search.h"
#include "fit/live_step.h"
#include "fit/nlopt_search.h"
#include "fit/paper_search.h"
#include "fit/restitution_fit.h"

namespace bouncefit {

namespace {

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void AddWarning(FitUpdate* u, const std::string& warning) {
  u->warning += (u->warning.empty() ? "" : "; ") + warning;
}

bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

std::string FormatNumber(double v, int precision = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", precision, v);
  return buf;
}
std::string FormatMm(double m) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f mm", m * 1000);
  return buf;
}
std::string FormatPercent(double f) { return FormatNumber(100 * f) + "%"; }

}  // namespace

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
  if (CanFit()) kept_.push_back({drop_height_m_, FittedHeights(), FittedFlights()});
  Reset(sequence);
}

bool FitSession::AddPeak(const PeakInput& p) {
  if (p.sequence != sequence_) return false;
  if (!std::isfinite(p.height_m) || p.bounce < 0) return true;  // nothing usable
  last_utime_ = p.utime;
  apexes_[p.bounce] = {p.height_m, p.sigma_m, p.impact_before_s};
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
    AddWarning(&u, "the flight times between impacts are " + FormatNumber(flight_clock_ratio_, 2) +
                       "x what the heights give (the impacts on another clock?): the heights alone are fitted");

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

FitProblem FitSession::WithSafety(FitProblem p) const {
  if (!config_.safe_search || config_.safe_drops_m.empty()) return p;
  const BallModel* model = p.model;
  // Whole drops, until the ball settles: the stored airball goes through the floor near
  // rest, 2 s after a 0.3 m drop, and a set that survives a 2 m drop's first two bounces
  // may still go through later. The fitted drop is checked to rest as well (the search's own
  // runs stop at the last recorded bounce). One thread: the starts keep the cores busy.
  std::vector<double> heights = config_.safe_drops_m;
  heights.push_back(p.simulation.drop_height_m);
  const double min_bounce = config_.safe_min_bounce_m;
  p.safety = [model, heights, min_bounce](const CoefficientValues& v) {
    return UnsafeDrop(*model, v, heights, 1, 0, min_bounce);
  };
  p.safety_simulations = static_cast<int>(heights.size());
  return p;
}

SearchResult FitSession::FinalSearch(int lead_n, int budget, const SearchOptions& options) const {
  const std::vector<CoefficientSpec> lead = FirstSpecs(initial_live_order_, lead_n);
  SearchOptions lo = options;
  lo.max_evaluations = budget / 10;
  LiveStepOptions ls;
  ls.rounds = 4;
  const SearchResult lr =
      LiveStep(WithSafety(MakeProblem(lead, final_start_)), final_start_, lo, ls);
  const CoefficientValues start = lr.evaluations > 0 ? lr.values : final_start_;
  SearchOptions o = options;
  o.max_evaluations = std::max(1, budget - lr.evaluations);
  const FitProblem p = WithSafety(MakeProblem(FreeSpecs(), start));
  SearchResult r = config_.method == "paper" ? PaperSearch(p, start, o) : NloptSearch(p, start, o);
  r.evaluations += lr.evaluations;
  r.safety_checks += lr.safety_checks;
  r.rejected_unsafe += lr.rejected_unsafe;
  return r;
}

FitUpdate FitSession::FinalUpdate(const CancelToken* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  // From the start of the drop (the table, or the previous drop's final fit), not from the
  // per-bounce updates': which of those finished depends on timing, and on chaotic heights a
  // different start is a different answer. The same peaks give the same final fit.
  // Several starts, best kept: each first does what the per-bounce updates do,
  // deterministically (Gauss-Newton rounds on the 2, 3, 4... most influential coefficients),
  // then the thorough search. On chaotic heights one search's answer is one draw.
  const int starts = std::max(1, config_.final_starts);
  const int k = static_cast<int>(FittedHeights().size());
  // The budget holds everything: the searches, the Jacobian (2 runs per coefficient + 2)
  // and the free-running check (one run per ensemble member), so progress never passes it.
  const int after_search = AfterSearchSimulations();
  const int budget = std::max(1, (config_.max_evaluations_final - after_search) / starts);
  SearchOptions o;
  o.threads = config_.threads;
  o.simulations = &simulations_;
  o.cancel = cancel;
  if (config_.target_rms_fraction > 0) o.target_rms_m = config_.target_rms_fraction * drop_height_m_;
  FitProblem restitution_problem;
  const bool restitution = UsesRestitutionLaw();
  SearchResult restitution_result;
  std::vector<std::string> held, held_why;
  if (restitution)
    restitution_result = FinalRestitutionSearch(budget * starts, o, &restitution_problem, &held, &held_why);
  // The starts' leads: 2, 3, 4... coefficients, never more than the bounces.
  std::vector<int> leads;
  for (int start_index = 0; start_index < starts && !restitution; ++start_index) {
    const int lead_n = std::max(1, std::min(2 + start_index, k));
    leads.push_back(lead_n);
    if (lead_n >= k) break;  // no other lead
  }
  // The starts are independent: on several cores they run at once, each on one thread (a
  // serial BOBYQA uses one core; three starts on two cores finish in 1.5 starts' time, not
  // 3). Each start is deterministic on its own, so the answer does not depend on the cores.
  std::vector<SearchResult> results(leads.size());
  const int threads = config_.threads > 0 ? config_.threads
                                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (threads > 1 && leads.size() > 1) {
    SearchOptions one = o;
    one.threads = std::max(1, threads / static_cast<int>(leads.size()));
    std::vector<std::future<SearchResult>> running;
    for (int lead_n : leads)
      running.push_back(std::async(std::launch::async, [&, lead_n] { return FinalSearch(lead_n, budget, one); }));
    for (size_t i = 0; i < running.size(); ++i) results[i] = running[i].get();
  } else {
    for (size_t i = 0; i < leads.size(); ++i) {
      results[i] = FinalSearch(leads[i], budget, o);
      if (cancel && cancel->cancelled()) break;  // cut short
    }
  }
  SearchResult r;
  int evaluations = 0, checks = 0, rejected = 0;
  for (size_t i = 0; i < results.size(); ++i) {
    evaluations += results[i].evaluations;
    checks += results[i].safety_checks;
    rejected += results[i].rejected_unsafe;
    if (i == 0 || (results[i].evaluations > 0 && results[i].objective < r.objective))
      r = std::move(results[i]);
  }
  if (restitution) {
    r = std::move(restitution_result);
    evaluations = r.evaluations;
    checks = r.safety_checks;
    rejected = r.rejected_unsafe;
  }
  r.evaluations = evaluations;
  r.safety_checks = checks;
  r.rejected_unsafe = rejected;
  r.wall_time_s = Seconds(t0);
  r.cancelled = r.cancelled || (cancel && cancel->cancelled());
  const FitProblem p = restitution ? restitution_problem : MakeProblem(FreeSpecs(), r.values);
  if (r.evaluations > 0) current_ = r.values;
  if (r.evaluations > 0 && !r.cancelled) final_start_ = r.values;
  // Uncertainty from the Jacobian at the answer (its own budget: 2 runs per coefficient).
  std::vector<std::vector<double>> jac;
  int extra = 0;
  if (!r.cancelled && !(cancel && cancel->cancelled())) {
    SearchOptions jo = o;
    jo.max_evaluations = 2 * static_cast<int>(p.free.size()) + 2;
    jo.target_rms_m = 0;
    FitObjective jf(p, jo);
    jac = HeightsJacobian(jf, r.values);
    extra = jf.evaluations();
    if (jf.cancelled()) jac.clear();
  }
  if (jac.empty()) jac = r.jacobian;
  // Live updates try the most sensitive coefficients first.
  if (!jac.empty()) {
    std::vector<std::pair<double, std::string>> effect;
    for (size_t j = 0; j < p.free.size(); ++j) {
      double e = 0;
      for (const auto& row : jac) e = std::max(e, std::abs(row[j]));
      effect.emplace_back(-e, p.free[j].name);
    }
    std::stable_sort(effect.begin(), effect.end());
    live_order_.clear();
    for (const auto& [e, name] : effect) live_order_.push_back(name);
  }
  FitUpdate u = Finish(p, r, true, jac, extra, Seconds(t0), model_);
  // The law's coefficients the bounces could not fit: the preset's value, said so.
  for (size_t i = 0; i < held.size(); ++i) {
    for (auto& c : u.coefficients)
      if (c.name == held[i]) {
        c.note = held_why[i] + "; the ball preset's value is used";
        c.identifiable = false;
        c.sigma = std::numeric_limits<double>::quiet_NaN();
        if (!Contains(u.unidentified, c.name)) u.unidentified.push_back(c.name);
      }
    u.held_at_preset.push_back(held[i] + " " + held_why[i] + "; the ball preset's value is used");
  }
  u.safety_checks = r.safety_checks;
  u.rejected_unsafe = r.rejected_unsafe;
  if (!r.failure.empty() && !r.cancelled)  // every point the search tried failed or was unsafe
    u.warning = "no usable coefficient set found: " + r.failure;
  if (!(cancel && cancel->cancelled())) CheckFreeRun(p, &u);
  // An answer only when the fitted ball's heights are as close as the measurement explains.
  if (!u.recorded_m.empty()) {
    const double highest = *std::max_element(u.recorded_m.begin(), u.recorded_m.end());
    const double sigma = MeasurementSigma();
    const double limit = std::max({config_.answer_floor_m, config_.answer_fraction * highest,
                                   config_.answer_sigmas * sigma});
    if (!r.failure.empty() && !r.cancelled)
      u.no_answer = u.warning;
    else if (!(u.residual_m <= limit))
      u.no_answer = "the fitted ball's heights are " + FormatMm(u.residual_m) +
                    " RMS from the recorded ones, more than their measurement explains (" +
                    FormatMm(limit) + ": the largest of " + FormatMm(config_.answer_floor_m) + ", " +
                    FormatPercent(config_.answer_fraction) + " of the highest apex and " +
                    FormatNumber(config_.answer_sigmas) + " x the heights' uncertainty " +
                    FormatMm(sigma) + ")";
  }
  u.wall_time_s = Seconds(t0);
  return u;
}

bool FitSession::UsesRestitutionLaw() const {
  if (config_.impact != "restitution" || !quick_model_) return false;
  for (const auto& s : model_.Coefficients())
    if (s.name == "rebound_restitution") return true;
  return false;
}

int FitSession::AfterSearchSimulations() const {
  const int drops = 1 + static_cast<int>(kept_.size());
  return 2 * static_cast<int>(FreeSpecs().size()) + 2 +
         drops * std::max(1, config_.ensemble_members) + 1 +
         static_cast<int>(config_.safe_drops_m.size());
}

int FitSession::FinalBudget() const {
  if (!UsesRestitutionLaw()) return config_.max_evaluations_final;
  const RestitutionFitOptions ro;
  const int search = std::min(ro.max_evaluations, config_.max_evaluations_final - AfterSearchSimulations());
  return ro.point_mass_evaluations + std::max(1, search) + AfterSearchSimulations();
}

SearchResult FitSession::FinalRestitutionSearch(int budget, const SearchOptions& options,
                                               FitProblem* p, std::vector<std::string>* held,
                                               std::vector<std::string>* held_why) const {
  RestitutionFitOptions ro;
  ro.segments = config_.objective == "segments";
  ro.max_evaluations = std::min(budget, ro.max_evaluations);
  ro.measurement_sigma_m = MeasurementSigma();
  const RestitutionFit rf =
      FitRestitutionCurve(WithSafety(MakeProblem(FreeSpecs(), final_start_)), *quick_model_, options, ro);
  std::vector<std::string> fitted;
  for (const std::string name : {"rebound_restitution", "rebound_restitution_per_mps", "drag"})
    if (!Contains(rf.held, name)) fitted.push_back(name);
  *p = MakeProblem(FirstSpecs(fitted, static_cast<int>(fitted.size())), rf.soft.values);
  *held = rf.held;
  *held_why = rf.held_why;
  return rf.soft;
}

void FitSession::CheckFreeRun(const FitProblem& p, FitUpdate* u) {
  // The free-running drop at the answer: one run exactly as `simulate` does it (so the export
  // reproduces these heights), and the ensemble around it, the honest error bar.
  DropEnsembleOptions eo;
  eo.members = std::max(1, config_.ensemble_members);
  eo.threads = config_.threads;
  // Each drop of a joint fit from its own height, its bounces in its own slots.
  DropEnsemble e;
  e.ok = true;
  for (size_t d = 0; d < p.Drops() && e.ok; ++d) {
    SimulationOptions drop = p.simulation;
    drop.drop_height_m = p.DropHeight(d);
    const size_t n = p.DropStart(d + 1) - p.DropStart(d);
    if (d > 0) {
      const std::vector<double> mine(p.recorded_m.begin() + static_cast<long>(p.DropStart(d)),
                                     p.recorded_m.begin() + static_cast<long>(p.DropStart(d + 1)));
      drop.duration_s = config_.duration_margin * FreeFallApexTime(drop.drop_height_m, mine, static_cast<int>(n)) + 0.2;
      drop.max_bounces = static_cast<int>(n);
    }
    const DropEnsemble one = SimulateDropEnsemble(model_, u->values, drop, eo);
    simulations_ += one.simulations;
    u->evaluations += one.simulations;
    if (!one.ok) {
      e.ok = false;
      e.failure = one.failure;
      break;
    }
    auto take = [n](std::vector<double>* to, const std::vector<double>& from) {
      for (size_t i = 0; i < n; ++i) to->push_back(i < from.size() ? from[i] : 0.0);
    };
    take(&e.single_m, one.single_m);
    take(&e.mean_m, one.mean_m);
    take(&e.sd_m, one.sd_m);
  }
  if (!e.ok) {  // simulated_m stays the search's own run at the answer (what simulate gives)
    AddWarning(u, "a perturbed free-running drop diverges: " + e.failure);
    return;
  }
  if (!config_.safe_drops_m.empty()) {
    const std::string unsafe =
        UnsafeDrop(model_, u->values, config_.safe_drops_m, config_.threads, 0, config_.safe_min_bounce_m);
    const int n = static_cast<int>(config_.safe_drops_m.size());
    simulations_ += n;
    u->evaluations += n;
    if (!unsafe.empty()) AddWarning(u, "the fitted ball " + unsafe);
  }
  auto first_k = [&](const std::vector<double>& v) {
    std::vector<double> out(p.recorded_m.size(), 0.0);
    for (size_t i = 0; i < out.size() && i < v.size(); ++i) out[i] = v[i];
    return out;
  };
  u->simulated_m = first_k(e.single_m);
  u->residual_m = RmsResidual(p.recorded_m, u->simulated_m);
  if (config_.ensemble_members > 0) {
    u->free_run_mean_m = first_k(e.mean_m);
    u->free_run_sd_m = first_k(e.sd_m);
    u->free_run_residual_m = RmsResidual(p.recorded_m, u->free_run_mean_m);
  }
}

}  // namespace bouncefit
