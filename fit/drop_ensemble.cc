#include "fit/drop_ensemble.h"

#include <fmt/format.h>

#include "fit/fit_objective.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <future>
#include <random>
#include <thread>

namespace bouncefit {

namespace {

// Runs job(i) for i in [0, n) on up to `threads` threads (0: all cores).
template <class Job>
void ParallelFor(int n, int threads, const Job& job) {
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i = next++; i < n; i = next++) job(i);
  };
  const int t = std::min(
      n, threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
  std::vector<std::future<void>> futures;
  for (int w = 1; w < t; ++w) futures.push_back(std::async(std::launch::async, work));
  work();
  for (auto& f : futures) f.get();
}

}  // namespace

std::string UnsafeDrop(const BallModel& model, const CoefficientValues& values,
                       const std::vector<double>& drops_m, int threads, int max_bounces,
                       double min_bounce_m) {
  std::vector<SimulationResult> results(drops_m.size());
  ParallelFor(static_cast<int>(drops_m.size()), threads, [&](int i) {
    SimulationOptions o;
    o.drop_height_m = drops_m[i];
    o.min_bounce_height_m = min_bounce_m;
    o.duration_s = 6 + 4 * drops_m[i];
    o.max_bounces = max_bounces;
    results[i] = SimulateSafely(model, values, o);
  });
  for (size_t i = 0; i < drops_m.size(); ++i)
    if (!results[i].ok) return fmt::format("diverges dropped from {:.3g} m ({})", drops_m[i], results[i].failure);
  return {};
}

DropEnsemble SimulateDropEnsemble(const BallModel& model, const CoefficientValues& values,
                                  const SimulationOptions& drop, const DropEnsembleOptions& o) {
  const int n = std::max(1, o.members);
  // The perturbations depend on the seed only: every coefficient set gets the same ones.
  std::vector<SimulationOptions> runs(static_cast<size_t>(n), drop);
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int m = 1; m < n; ++m) {
    runs[m].drop_height_m = drop.drop_height_m + o.height_jitter_m * unit(rng);
    runs[m].release_turn_rad = drop.release_turn_rad + o.turn_jitter_rad * unit(rng);
  }
  std::vector<SimulationResult> results(static_cast<size_t>(n));
  ParallelFor(n, o.threads, [&](int m) { results[m] = SimulateSafely(model, values, runs[m]); });

  DropEnsemble e;
  e.simulations = n;
  for (const auto& r : results)
    if (!r.ok) {
      e.failure = r.failure.empty() ? "simulation failed" : r.failure;
      return e;
    }
  e.single_m = results[0].bounce_heights_m;
  size_t longest = 0;
  for (const auto& r : results) {
    e.runs.push_back(r.bounce_heights_m);
    longest = std::max(longest, r.bounce_heights_m.size());
  }
  for (size_t i = 0; i < longest; ++i) {
    double sum = 0, sum2 = 0;
    int count = 0;
    for (const auto& h : e.runs)
      if (i < h.size()) sum += h[i], sum2 += h[i] * h[i], ++count;
    if (2 * count < n) break;
    const double mean = sum / count;
    e.mean_m.push_back(mean);
    e.sd_m.push_back(count > 1 ? std::sqrt(std::max(0.0, (sum2 - count * mean * mean) / (count - 1))) : 0.0);
  }
  e.ok = true;
  return e;
}

}  // namespace bouncefit
