#include "pipeline/offline_fit.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <future>
#include <stdexcept>

#include "msgs/peaks_csv.h"

namespace bouncefit {

std::vector<std::vector<PeakInput>> ReadPeaksDrops(const std::filesystem::path& path,
                                                   std::vector<int>* drop_numbers) {
  std::vector<std::vector<PeakInput>> drops;
  std::vector<int> numbers;
  for (const PeaksCsvRow& r : ReadPeaksCsv(path)) {
    PeakInput p;
    p.bounce = r.bounce;
    p.height_m = r.HeightToUse();
    if (!std::isfinite(p.height_m)) throw std::runtime_error(path.string() + ": bounce " + std::to_string(r.bounce) + " has no height");
    p.utime = static_cast<int64_t>(std::llround(r.t_s * 1e6));
    // The detector's drops each have their own scale: never one fit's run across two.
    if (drops.empty() || r.bounce == 0 || r.bounce <= drops.back().back().bounce || r.drop != numbers.back()) {
      drops.emplace_back();
      numbers.push_back(r.drop);
    }
    drops.back().push_back(p);
  }
  if (drop_numbers) *drop_numbers = numbers;
  if (drops.empty()) throw std::runtime_error(path.string() + ": no rows (no bounce was found in that run)");
  return drops;
}

std::vector<PeakInput> ReadDropPeaks(const std::filesystem::path& path) { return ReadPeaksDrops(path).front(); }

FitUpdate FitDropsOffline(std::vector<std::vector<PeakInput>> drops, const FitSetup& setup, bool final_only,
                          const std::function<void(const FitUpdate&)>& emit,
                          const std::function<void(int, int)>& progress,
                          std::vector<std::pair<size_t, int>>* fitted) {
  std::vector<std::pair<size_t, int>> kept;  // the drops the session keeps, as it keeps them
  for (size_t d = 0; d < drops.size(); ++d)
    for (auto& p : drops[d]) p.sequence = static_cast<int>(d);
  const FitModels models = MakeFitModels(setup);
  FitSession session(*models.model, models.quick.get(), models.session);
  // As the fit stage would: the point-mass estimate and a refinement after every bounce (no
  // newer peak ever supersedes them offline), then the final fit; earlier drops are kept
  // and fitted with the last one.
  for (size_t d = 0; d < drops.size(); ++d) {
    if (d > 0) {
      if (session.CanFit()) kept.push_back({d - 1, session.start_bounce()});
      session.KeepDropAndReset(static_cast<int>(d));
    }
    for (const auto& p : drops[d]) {
      session.AddPeak(p);
      if (final_only || p.bounce < 1 || !session.CanFit()) continue;
      if (session.bounces() < p.bounce) continue;  // below 1 cm, or not after the start
      emit(session.QuickUpdate());
      emit(session.Update());
    }
  }
  if (!session.CanFit())
    throw std::runtime_error(fmt::format("no fit: no drop has two apexes in a row (a start and a rebound after it) "
                                         "of {:g} cm or more",
                                         models.session.min_bounce_height_m * 100));
  if (final_only) emit(session.QuickUpdate());
  auto running = std::async(std::launch::async, [&session] { return session.FinalUpdate(); });
  const int budget = session.FinalBudget();
  const int before = session.simulations();
  while (running.wait_for(std::chrono::seconds(1)) != std::future_status::ready)
    if (progress) progress(session.simulations() - before, budget);
  const FitUpdate final_fit = running.get();
  if (fitted) {
    *fitted = {{drops.size() - 1, final_fit.start_bounce}};
    fitted->insert(fitted->end(), kept.begin(), kept.end());
  }
  emit(final_fit);
  return final_fit;
}

std::vector<FitDrop> OfflineFitDrops(const FitUpdate& fit, const std::vector<std::vector<PeakInput>>& drops,
                                     const std::vector<std::pair<size_t, int>>& fitted) {
  const std::vector<FitDropSlice> slices = FitDropSlices(fit);
  std::vector<FitDrop> out;
  for (size_t k = 0; k < slices.size() && k < fitted.size(); ++k) {
    const auto [index, start] = fitted[k];
    auto time_of = [&](int bounce) {
      for (const PeakInput& p : drops.at(index))
        if (p.bounce == bounce) return static_cast<double>(p.utime) * 1e-6;
      return std::nan("");
    };
    FitDrop d;
    d.drop = static_cast<int>(index);
    d.start_bounce = start;
    d.start_t_s = time_of(start);
    d.start_height_m = slices[k].start_height_m;
    for (size_t i = 0; i < slices[k].count; ++i) {
      const int bounce = start + 1 + static_cast<int>(i);
      d.bounces.push_back(bounce);
      d.apex_t_s.push_back(time_of(bounce));
      d.recorded_m.push_back(fit.recorded_m[slices[k].first + i]);
      d.simulated_m.push_back(slices[k].first + i < fit.simulated_m.size() ? fit.simulated_m[slices[k].first + i]
                                                                            : std::nan(""));
    }
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace bouncefit
