#include "fit/fit_timeline.h"

#include <algorithm>

namespace bouncefit {

std::vector<FitDropSlice> FitDropSlices(const FitUpdate& u) {
  size_t others = 0;
  for (int n : u.other_drop_bounces) others += static_cast<size_t>(std::max(0, n));
  const size_t total = u.recorded_m.size();
  std::vector<FitDropSlice> slices;
  slices.push_back({0, total > others ? total - others : 0, u.drop_height_m});
  size_t at = slices.front().count;
  for (size_t d = 0; d < u.other_drop_bounces.size(); ++d) {
    const size_t n = std::min(static_cast<size_t>(std::max(0, u.other_drop_bounces[d])), total - std::min(at, total));
    slices.push_back({at, n, d < u.other_drop_heights_m.size() ? u.other_drop_heights_m[d] : std::nan("")});
    at += n;
  }
  return slices;
}

nlohmann::json FitDropsToJson(const std::vector<FitDrop>& drops) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  auto nums = [&](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v) a.push_back(num(x));
    return a;
  };
  nlohmann::json out = nlohmann::json::array();
  for (const FitDrop& d : drops) {
    nlohmann::json j = {{"drop", d.drop},
                        {"start_bounce", d.start_bounce},
                        {"start_t_s", num(d.start_t_s)},
                        {"start_height_m", num(d.start_height_m)},
                        {"bounces", d.bounces},
                        {"apex_t_s", nums(d.apex_t_s)},
                        {"recorded_m", nums(d.recorded_m)},
                        {"simulated_m", nums(d.simulated_m)}};
    if (!d.clip.empty()) j["clip"] = d.clip;
    out.push_back(j);
  }
  return out;
}

double RunSecondsPerRealSecond(const std::vector<FitDrop>& drops,
                               const std::vector<std::vector<double>>& simulated_apex_times_s) {
  double run_sim = 0, sim_sim = 0;
  for (size_t d = 0; d < drops.size() && d < simulated_apex_times_s.size(); ++d) {
    const FitDrop& drop = drops[d];
    for (size_t i = 0; i < drop.apex_t_s.size() && i < simulated_apex_times_s[d].size(); ++i) {
      const double run = drop.apex_t_s[i] - drop.start_t_s, sim = simulated_apex_times_s[d][i];
      if (!std::isfinite(run) || !std::isfinite(sim) || !(sim > 0)) continue;
      run_sim += run * sim;
      sim_sim += sim * sim;
    }
  }
  if (!(sim_sim > 0)) return 1;
  const double r = run_sim / sim_sim;
  if (!(r > 0) || std::abs(r - 1) < 0.15) return 1;
  const double whole = std::round(r >= 1 ? r : 1 / r);  // a phone slows by a whole factor
  if (whole >= 2 && std::abs((r >= 1 ? r : 1 / r) / whole - 1) < 0.05) return r >= 1 ? whole : 1 / whole;
  return r;
}

SimulationResult SimulateFromStart(const BallModel& model, const CoefficientValues& values,
                                   double start_height_m, double duration_s, double min_hop_m,
                                   double rate_hz) {
  SimulationOptions so;
  so.drop_height_m = start_height_m;
  so.min_bounce_height_m = min_hop_m;
  so.record_trajectory = true;
  so.trajectory_rate_hz = rate_hz;
  so.duration_s = duration_s;
  return model.Simulate(values, so);
}

}  // namespace bouncefit
