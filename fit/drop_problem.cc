#include "fit/drop_problem.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fit/drop_ensemble.h"

namespace bouncefit {

DropProblems::DropProblems(const BallModel& model, const FitSessionConfig& config, const RecordedDrop& drop,
                           const std::vector<KeptDrop>& kept)
    : model_(model), config_(config), drop_(drop), kept_(kept) {}

FitProblem DropProblems::Make(const std::vector<CoefficientSpec>& free, const CoefficientValues& at,
                              bool live) const {
  FitProblem p;
  p.model = &model_;
  p.free = free;
  p.fixed = at;
  p.recorded_m = drop_.fitted_heights();
  p.recorded_flight_s = drop_.fitted_flights();
  p.flight_weight_mps = config_.impact == "restitution" ? config_.flight_weight_mps : 0;
  // The first fall on the heights' clock: the impacts' divided by the flights' ratio to it when
  // the drop found them on another (a slow-motion file).
  const double ratio = drop_.flight_clock_ratio();
  const double heights_s_per_stream_s = std::isfinite(ratio) ? 1 / ratio : 1;
  p.start_fall_s = drop_.StartFall() * heights_s_per_stream_s;
  p.start_fall_sigma_s = config_.time_sigma_s * heights_s_per_stream_s;
  p.segments = config_.objective == "segments";
  for (const auto& [name, step] : config_.grid) p.grid[name] = step;
  if (p.recorded_m.empty()) throw std::logic_error("no bounce to fit yet");
  const int k = static_cast<int>(p.recorded_m.size());
  const double drop_height_m = drop_.drop_height_m();
  p.simulation.drop_height_m = drop_height_m;
  const double t_k = FreeFallApexTime(drop_height_m, p.recorded_m, k);
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

FitProblem DropProblems::WithSafety(FitProblem p) const {
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

}  // namespace bouncefit
