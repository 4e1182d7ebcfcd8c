#include "fit/fit_objective.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <stdexcept>
#include <thread>

namespace bouncefit {

namespace {
constexpr double kGravity = 9.81;
constexpr double kCacheTolerance = 1e-12;
// Set on EvaluateBatch's workers: evaluations already run in parallel, their segments not.
thread_local bool t_in_batch = false;
}  // namespace

SimulationResult SimulateSafely(const BallModel& model, const CoefficientValues& values,
                                const SimulationOptions& options) {
  try {
    return model.Simulate(values, options);
  } catch (const std::exception& ex) {
    SimulationResult r;
    r.failure = ex.what();
    return r;
  }
}

size_t FitProblem::DropStart(size_t d) const {
  size_t others = 0;
  for (const auto& o : other_drops) others += static_cast<size_t>(std::max(0, o.bounces));
  const size_t first = recorded_m.size() - std::min(others, recorded_m.size());
  if (d == 0) return 0;
  size_t at = first;
  for (size_t j = 0; j + 1 < d && j < other_drops.size(); ++j)
    at += static_cast<size_t>(std::max(0, other_drops[j].bounces));
  return std::min(d > other_drops.size() ? recorded_m.size() : at, recorded_m.size());
}

double FitProblem::DropHeight(size_t d) const {
  return d == 0 ? simulation.drop_height_m : other_drops.at(d - 1).drop_height_m;
}

double HeightObjective(const std::vector<double>& recorded, const std::vector<double>& simulated) {
  double sum = 0;
  for (size_t i = 0; i < recorded.size(); ++i) {
    const double s = i < simulated.size() ? simulated[i] : 0.0;
    sum += (recorded[i] - s) * (recorded[i] - s);
  }
  return sum;
}

double RmsResidual(const std::vector<double>& recorded, const std::vector<double>& simulated) {
  if (recorded.empty()) return 0;
  return std::sqrt(HeightObjective(recorded, simulated) / static_cast<double>(recorded.size()));
}

std::vector<double> FlightTimes(const std::vector<double>& impacts, size_t k) {
  std::vector<double> out(k, 0.0);
  for (size_t i = 0; i < k && i + 1 < impacts.size(); ++i) out[i] = impacts[i + 1] - impacts[i];
  return out;
}

double FreeFallApexTime(double drop_height_m, const std::vector<double>& heights_m, int k) {
  double t = std::sqrt(2 * std::max(drop_height_m, 0.0) / kGravity);
  for (int i = 0; i < k && i < static_cast<int>(heights_m.size()); ++i) {
    const double h = std::max(heights_m[i], 0.0);
    t += std::sqrt(2 * h / kGravity) * (i + 1 < k ? 2 : 1);
  }
  return t;
}

int PaperPriority(const std::string& name) {
  // Keyword rules, checked in order; the first that matches gives the rank.
  struct Rule {
    const char* keyword;
    int rank;
  };
  static const Rule rules[] = {
      {"linear", 0},      {"angular", 1},      {"volume_stiff", 2}, {"pressure", 3},
      {"damping", 4},     {"drag", 5},         {"lift", 6},         {"rigid", 7},
      {"kinetic", 8},     {"soft_soft", 9},    {"resolution", 10},  {"radius_edge", 11},
      {"max_volume", 12}, {"volume_constr", 12}, {"restitution_per", 1}, {"restitution", 0},
  };
  for (const auto& r : rules)
    if (name.find(r.keyword) != std::string::npos) return r.rank;
  return 100;
}

FitObjective::FitObjective(FitProblem problem, SearchOptions options)
    : problem_(std::move(problem)), options_(options) {
  if (!problem_.model) throw std::invalid_argument("fit problem without a model");
  if (problem_.recorded_m.empty()) throw std::invalid_argument("fit problem without heights");
  for (const auto& spec : problem_.free)
    if (!(spec.upper >= spec.lower))
      throw std::invalid_argument("coefficient '" + spec.name + "' has empty bounds");
  threads_ = options_.threads > 0 ? options_.threads
                                   : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  // A failed simulation scores worse than any simulated heights between 0 and the drop.
  double worst = 0;
  for (double r : problem_.recorded_m) {
    const double w = std::max(r, problem_.simulation.drop_height_m - r);
    worst += w * w;
  }
  penalty_ = 2 * worst + 1e-3;
}

double FitObjective::Level(size_t j) const {
  const auto& s = problem_.free[j];
  const double range = s.upper - s.lower;
  if (!(range > 0)) return 0;
  auto it = problem_.grid.find(s.name);
  if (it != problem_.grid.end() && it->second > 0) return std::min(1.0, it->second / range);
  return s.discrete ? std::min(1.0, 1.0 / range) : 0.0;
}

CoefficientValues FitObjective::ToValues(const std::vector<double>& x_in) const {
  std::vector<double> x = x_in;
  x.resize(problem_.free.size(), 0.0);
  Snap(&x);
  CoefficientValues v = problem_.fixed;
  for (size_t j = 0; j < problem_.free.size(); ++j) {
    const auto& s = problem_.free[j];
    double value = s.lower + x[j] * (s.upper - s.lower);
    if (s.discrete) value = std::round(value);
    v[s.name] = std::clamp(value, s.lower, s.upper);
  }
  return v;
}

std::vector<double> FitObjective::ToUnit(const CoefficientValues& values) const {
  std::vector<double> x(problem_.free.size());
  for (size_t j = 0; j < problem_.free.size(); ++j) {
    const auto& s = problem_.free[j];
    auto it = values.find(s.name);
    const double value = it != values.end() ? it->second : s.default_value;
    const double range = s.upper - s.lower;
    x[j] = range > 0 ? std::clamp((value - s.lower) / range, 0.0, 1.0) : 0.0;
  }
  return x;
}

void FitObjective::Snap(std::vector<double>* x) const {
  for (size_t j = 0; j < problem_.free.size() && j < x->size(); ++j) {
    (*x)[j] = std::clamp((*x)[j], 0.0, 1.0);
    const double level = Level(j);
    if (level > 0) {
      const double steps = std::floor(1.0 / level + 1e-9);
      (*x)[j] = std::min(std::round((*x)[j] / level), steps) * level;
    }
  }
}

bool FitObjective::cancelled() const { return options_.cancel && options_.cancel->cancelled(); }

bool FitObjective::stopped() const {
  if (cancelled()) return true;
  if (reserved_.load() >= options_.max_evaluations) return true;
  if (options_.target_rms_m > 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double target =
        options_.target_rms_m * options_.target_rms_m * problem_.recorded_m.size();
    if (have_best_ && best_.ok && best_.objective <= target) return true;
  }
  return false;
}

bool FitObjective::Lookup(const std::vector<double>& x, Evaluation* out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [cx, e] : cache_) {
    bool same = cx.size() == x.size();
    for (size_t j = 0; same && j < x.size(); ++j) same = std::abs(cx[j] - x[j]) <= kCacheTolerance;
    if (same) {
      *out = e;
      return true;
    }
  }
  return false;
}

void FitObjective::Record(const std::vector<double>& x, const Evaluation& e) {
  std::lock_guard<std::mutex> lock(mutex_);
  cache_.emplace_back(x, e);
  if (!have_best_ || e.objective < best_.objective) {
    best_ = e;
    best_x_ = x;
    have_best_ = true;
  }
  history_.push_back(best_.objective);
}

Evaluation FitObjective::Run(const std::vector<double>& x_in) {
  std::vector<double> x = x_in;
  Snap(&x);
  Evaluation e;
  if (Lookup(x, &e)) return e;
  if (cancelled() || reserved_.fetch_add(1) >= options_.max_evaluations) {
    e.skipped = true;
    e.objective = penalty_;
    e.failure = cancelled() ? "cancelled" : "evaluation budget used";
    return e;
  }
  std::vector<double> flights;
  const SimulationResult sim = Simulate(ToValues(x), !t_in_batch && threads_ > 1, &flights);
  ++evaluations_;
  if (options_.simulations) options_.simulations->fetch_add(1);
  e.ok = sim.ok;
  if (sim.ok) {
    e.simulated_m.assign(problem_.recorded_m.size(), 0.0);
    for (size_t i = 0; i < e.simulated_m.size() && i < sim.bounce_heights_m.size(); ++i)
      e.simulated_m[i] = sim.bounce_heights_m[i];
    e.simulated_flight_s = flights;
    e.objective = 0;
    for (double r : Residuals(e)) e.objective += r * r;
    if (!std::isfinite(e.objective)) {
      e.ok = false;
      e.failure = "non-finite heights";
    }
  } else {
    e.failure = sim.failure.empty() ? "simulation failed" : sim.failure;
  }
  if (e.ok && problem_.safety && BeatsBest(e.objective)) CheckSafety(x, &e);
  if (!e.ok) e.objective = penalty_;
  Record(x, e);
  return e;
}

bool FitObjective::BeatsBest(double objective) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !have_best_ || objective < best_.objective;
}

void FitObjective::CheckSafety(const std::vector<double>& x, Evaluation* e) {
  // Only candidates for the answer are checked; the best is only ever a checked point. The
  // check's runs take budget slots like any simulation (progress never passes the budget).
  const int n = std::max(0, problem_.safety_simulations);
  if (reserved_.fetch_add(n) + n > options_.max_evaluations) {
    reserved_ -= n;
    e->ok = false;
    e->failure = "no budget left to check its safety";
    return;
  }
  const std::string unsafe = problem_.safety(ToValues(x));
  evaluations_ += n;
  if (options_.simulations) options_.simulations->fetch_add(n);
  ++safety_checks_;
  if (unsafe.empty()) return;
  ++rejected_unsafe_;
  e->ok = false;
  e->failure = "unsafe: " + unsafe;
}

bool FitObjective::timed() const {
  if (!(problem_.flight_weight_mps > 0)) return false;
  for (double f : problem_.recorded_flight_s)
    if (std::isfinite(f)) return true;
  return false;
}

std::vector<double> FitObjective::Residuals(const Evaluation& e) const {
  std::vector<double> r;
  for (size_t i = 0; i < problem_.recorded_m.size(); ++i)
    r.push_back(problem_.recorded_m[i] - (i < e.simulated_m.size() ? e.simulated_m[i] : 0.0));
  if (!timed()) return r;
  for (size_t i = 0; i < problem_.recorded_flight_s.size() && i < problem_.recorded_m.size(); ++i)
    if (std::isfinite(problem_.recorded_flight_s[i])) {
      // A flight f weighs as the flight-time height g f^2 / 8 it gives (dh/df = g f / 4), at
      // most flight_weight_mps: a short hop's flight, timed to a few ms like a long one's,
      // tells its height less well and must not outweigh it.
      const double w = std::min(problem_.flight_weight_mps, 9.81 * problem_.recorded_flight_s[i] / 4);
      r.push_back(w * (problem_.recorded_flight_s[i] -
                       (i < e.simulated_flight_s.size() ? e.simulated_flight_s[i] : 0.0)));
    }
  return r;
}

SimulationResult FitObjective::Simulate(const CoefficientValues& values, bool parallel,
                                        std::vector<double>* flights) const {
  const size_t k = problem_.recorded_m.size();
  if (!problem_.segments && problem_.other_drops.empty()) {
    SimulationResult r = SimulateSafely(*problem_.model, values, problem_.simulation);
    *flights = FlightTimes(r.impact_times_s, k);
    return r;
  }
  if (!problem_.segments) {
    // Several drops: each from its own height, its heights and flights in its own slots.
    SimulationResult out;
    out.ok = true;
    flights->clear();
    for (size_t d = 0; d < problem_.Drops(); ++d) {
      const size_t from = problem_.DropStart(d), to = problem_.DropStart(d + 1);
      const std::vector<double> mine(problem_.recorded_m.begin() + static_cast<long>(from),
                                     problem_.recorded_m.begin() + static_cast<long>(to));
      SimulationOptions o = problem_.simulation;
      o.drop_height_m = problem_.DropHeight(d);
      if (d > 0) {
        const int n = static_cast<int>(mine.size());
        o.duration_s = 1.5 * FreeFallApexTime(o.drop_height_m, mine, n) + 0.2;
        o.max_bounces = n;
      }
      const SimulationResult r = SimulateSafely(*problem_.model, values, o);
      if (!r.ok) {
        out.ok = false;
        out.failure = "drop " + std::to_string(d + 1) + " (" + std::to_string(o.drop_height_m) +
                      " m): " + r.failure;
        return out;
      }
      for (size_t i = 0; i < mine.size(); ++i)
        out.bounce_heights_m.push_back(i < r.bounce_heights_m.size() ? r.bounce_heights_m[i] : 0.0);
      const std::vector<double> f = FlightTimes(r.impact_times_s, mine.size());
      flights->insert(flights->end(), f.begin(), f.end());
      out.wall_time_s += r.wall_time_s;
    }
    return out;
  }
  std::vector<SimulationResult> runs(k);
  const bool timing = timed();
  auto segment = [&](size_t i) {
    SimulationOptions o = problem_.simulation;
    o.record_trajectory = false;
    // Bounce i from the recorded apex before it, or from its drop's release height.
    o.drop_height_m = problem_.recorded_m.empty() ? 0 : problem_.simulation.drop_height_m;
    for (size_t d = 0; d < problem_.Drops(); ++d)
      if (i == problem_.DropStart(d)) o.drop_height_m = problem_.DropHeight(d);
      else if (i > problem_.DropStart(d) && i < problem_.DropStart(d + 1))
        o.drop_height_m = problem_.recorded_m[i - 1];
    // Long enough for the first apex (and the samples after it that measure it), or with
    // timing for the impact that ends its arc.
    const double h = problem_.recorded_m[i];
    o.duration_s = timing ? std::sqrt(2 * o.drop_height_m / kGravity) + 2 * std::sqrt(2 * h / kGravity) + 0.1
                          : 1.5 * FreeFallApexTime(o.drop_height_m, {h}, 1) + 0.2;
    o.max_bounces = 1;  // stops at the impact that ends the arc
    runs[i] = SimulateSafely(*problem_.model, values, o);
  };
  if (parallel) {
    std::atomic<size_t> next{0};
    auto work = [&] {
      for (size_t i = next++; i < k; i = next++) segment(i);
    };
    std::vector<std::future<void>> futures;
    for (int w = 1; w < std::min<int>(threads_, static_cast<int>(k)); ++w)
      futures.push_back(std::async(std::launch::async, work));
    work();
    for (auto& f : futures) f.get();
  } else {
    for (size_t i = 0; i < k; ++i) segment(i);
  }
  SimulationResult out;
  out.ok = true;
  flights->assign(k, 0.0);
  for (size_t i = 0; i < k; ++i) {
    if (!runs[i].ok) {
      out.ok = false;
      out.failure = "segment " + std::to_string(i + 1) + ": " + runs[i].failure;
      return out;
    }
    out.bounce_heights_m.push_back(runs[i].bounce_heights_m.empty() ? 0.0
                                                                     : runs[i].bounce_heights_m[0]);
    (*flights)[i] = FlightTimes(runs[i].impact_times_s, 1)[0];
    out.wall_time_s += runs[i].wall_time_s;
  }
  return out;
}

Evaluation FitObjective::Evaluate(const std::vector<double>& x) {
  if (stopped()) {
    Evaluation e;
    std::vector<double> snapped = x;
    Snap(&snapped);
    if (Lookup(snapped, &e)) return e;
    e.skipped = true;
    e.objective = penalty_;
    e.failure = cancelled() ? "cancelled" : "stopped";
    return e;
  }
  return Run(x);
}

std::vector<Evaluation> FitObjective::EvaluateBatch(const std::vector<std::vector<double>>& xs) {
  std::vector<Evaluation> out(xs.size());
  const int workers = std::min<int>(threads_, static_cast<int>(xs.size()));
  if (workers <= 1) {
    for (size_t i = 0; i < xs.size(); ++i) out[i] = Evaluate(xs[i]);
    return out;
  }
  std::atomic<size_t> next{0};
  auto work = [&] {
    t_in_batch = true;
    for (size_t i = next++; i < xs.size(); i = next++) out[i] = Evaluate(xs[i]);
    t_in_batch = false;
  };
  std::vector<std::future<void>> futures;
  for (int w = 1; w < workers; ++w) futures.push_back(std::async(std::launch::async, work));
  work();
  for (auto& f : futures) f.get();
  return out;
}

std::vector<double> FitObjective::best_x() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return best_x_;
}

Evaluation FitObjective::best() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return best_;
}

std::vector<double> FitObjective::best_history() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return history_;
}

SearchResult FitObjective::MakeResult(const std::string& method, double wall_time_s) const {
  SearchResult r;
  r.method = method;
  std::lock_guard<std::mutex> lock(mutex_);
  if (have_best_) {
    r.values = ToValues(best_x_);
    r.simulated_m = best_.simulated_m;
    r.objective = best_.objective;
    if (!best_.ok) r.failure = best_.failure.empty() ? "simulation failed" : best_.failure;
  } else {
    r.failure = "no simulation ran";
    r.values = ToValues(std::vector<double>(problem_.free.size(), 0.0));
    r.objective = penalty_;
  }
  r.simulated_m.resize(problem_.recorded_m.size(), 0.0);
  r.rms_m = std::sqrt(r.objective / static_cast<double>(problem_.recorded_m.size()));
  r.evaluations = evaluations_.load();
  r.safety_checks = safety_checks_.load();
  r.rejected_unsafe = rejected_unsafe_.load();
  r.wall_time_s = wall_time_s;
  r.cancelled = options_.cancel && options_.cancel->cancelled();
  r.best_history = history_;
  return r;
}

}  // namespace bouncefit
