#include "cli/fit_offline.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <sstream>
#include <stdexcept>

#include "fit/fit_models.h"
#include "model/model_by_name.h"
#include "model/point_mass_model.h"

namespace bouncefit::cli {
namespace {

std::string Fmt(double v, int digits = 4) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace

std::vector<PeakInput> ReadPeaksCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty");
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    std::string col;
    while (std::getline(ss, col, ',')) header.push_back(col);
  }
  auto index = [&](const std::string& name) {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  };
  // The fused height (from the flight time where the impacts were heard) where there is one.
  const int ib = index("bounce"), ih = index("height_m"), it = index("t_s"), ifu = index("fused_height_m");
  if (ib < 0 || ih < 0) throw std::runtime_error(path + ": needs columns bounce and height_m");
  std::vector<PeakInput> peaks;
  int drops = 0;
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (static_cast<int>(cells.size()) <= std::max(ib, ih))
      throw std::runtime_error(path + ":" + std::to_string(row) + ": too few columns");
    PeakInput p;
    try {
      p.bounce = std::stoi(cells[ib]);
      p.height_m = std::stod(ifu >= 0 && ifu < static_cast<int>(cells.size()) && !cells[ifu].empty()
                                 ? cells[ifu]
                                 : cells[ih]);
      if (it >= 0 && it < static_cast<int>(cells.size()) && !cells[it].empty())
        p.utime = static_cast<int64_t>(std::llround(std::stod(cells[it]) * 1e6));
    } catch (const std::exception&) {
      throw std::runtime_error(path + ":" + std::to_string(row) + ": not a number");
    }
    if (p.bounce == 0 && ++drops > 1) break;
    peaks.push_back(p);
  }
  if (peaks.empty()) throw std::runtime_error(path + ": no rows (no bounce was found in that run)");
  if (peaks.front().bounce != 0)
    throw std::runtime_error(path + ": the first peak must be bounce 0 (the release height; the "
                             "release was not seen)");
  return peaks;
}

void PrintFitUpdate(const FitUpdate& u) {
  std::printf("%s fit after bounce %d  [%s, %s]: RMS residual %s mm over %zu bounces, "
              "%d simulations, %.2f s%s\n",
              u.final ? "FINAL" : (u.model == "point-mass" ? "quick" : "bounce"),
              u.after_bounce, u.model.c_str(), u.method.c_str(), Fmt(u.residual_m * 1000, 3).c_str(),
              u.recorded_m.size(), u.evaluations, u.wall_time_s, u.cancelled ? " (cut short)" : "");
  for (const auto& c : u.coefficients) {
    const std::string unit = c.unit.empty() ? "" : " " + c.unit;
    if (c.identifiable)
      std::printf("  %-28s %12s +- %-10s%s\n", c.name.c_str(), Fmt(c.value, 6).c_str(),
                  Fmt(c.sigma, 2).c_str(), unit.c_str());
    else
      std::printf("  %-28s %12s %s  (%s)\n", c.name.c_str(), Fmt(c.value, 6).c_str(),
                  unit.c_str(), c.note.empty() ? "not identifiable" : c.note.c_str());
  }
  std::printf("  recorded  (m):");
  for (double r : u.recorded_m) std::printf(" %.4f", r);
  std::printf("\n  simulated (m):");
  for (double s : u.simulated_m) std::printf(" %.4f", s);
  std::printf("\n");
  if (!u.other_drop_heights_m.empty()) {  // a joint fit: which bounces are which drop's
    size_t first = u.recorded_m.size();
    for (int n : u.other_drop_bounces) first -= static_cast<size_t>(n);
    std::printf("  drops: %.4f m (bounces 1-%zu)", u.drop_height_m, first);
    size_t at = first;
    for (size_t d = 0; d < u.other_drop_heights_m.size(); ++d) {
      std::printf(", %.4f m (%zu-%zu)", u.other_drop_heights_m[d], at + 1,
                  at + static_cast<size_t>(u.other_drop_bounces[d]));
      at += static_cast<size_t>(u.other_drop_bounces[d]);
    }
    std::printf("\n");
  }
  if (!u.segment_simulated_m.empty()) {
    std::printf("  segments  (m):");  // bounce i from the recorded apex i-1
    for (double s : u.segment_simulated_m) std::printf(" %.4f", s);
    std::printf("   RMS %s mm\n", Fmt(u.segment_residual_m * 1000, 3).c_str());
  }
  if (!u.free_run_mean_m.empty()) {
    std::printf("  free drop, ensemble mean +- sd (m):");
    for (size_t i = 0; i < u.free_run_mean_m.size(); ++i)
      std::printf(" %.4f+-%.4f", u.free_run_mean_m[i], u.free_run_sd_m[i]);
    std::printf("   RMS %s mm\n", Fmt(u.free_run_residual_m * 1000, 3).c_str());
  }
  if (!u.warning.empty()) std::printf("  warning: %s\n", u.warning.c_str());
  if (u.time_step_s > 0)
    std::printf("  holds for time step %.6g s, %d position iterations\n", u.time_step_s,
                u.iterations);
  std::fflush(stdout);
}

FitUpdate FitDropsOffline(std::vector<std::vector<PeakInput>> drops, FitNodeConfig node,
                          bool final_only, const std::function<void(const FitUpdate&)>& emit,
                          bool progress) {
  for (size_t d = 0; d < drops.size(); ++d)
    for (auto& p : drops[d]) p.sequence = static_cast<int>(d);
  const BallPreset ball = ResolveBallPreset(node.ball, node.diameter_m, node.mass_kg);
  auto model = MakeBallModel(node.model, ball);
  PointMassModel quick(ball);
  ConfigureSessionForModel(*model, ball, &node.session);
  FitSession session(*model, &quick, node.session);
  // As the node would: the point-mass estimate and a refinement after every bounce (no
  // newer peak ever supersedes them offline), then the final fit.
  // Earlier drops are kept and fitted with the last one (issue 14 item 4).
  for (size_t d = 0; d < drops.size(); ++d) {
    if (d > 0) session.KeepDropAndReset(static_cast<int>(d));
    for (const auto& p : drops[d]) {
      session.AddPeak(p);
      if (final_only || p.bounce < 1 || !session.CanFit()) continue;
      if (static_cast<int>(session.FittedHeights().size()) < p.bounce) continue;  // below 1 cm
      emit(session.QuickUpdate());
      emit(session.Update());
    }
  }
  if (!session.CanFit())
    throw std::runtime_error("no bounce above " +
                             Fmt(node.session.min_bounce_height_m * 100, 3) + " cm to fit");
  if (final_only) emit(session.QuickUpdate());
  // The final fit takes seconds: its progress on stderr (stdout carries the updates).
  auto running = std::async(std::launch::async, [&session] { return session.FinalUpdate(); });
  const int budget = session.FinalBudget();
  const int before = session.simulations();
  while (running.wait_for(std::chrono::seconds(1)) != std::future_status::ready) {
    if (progress)
      std::fprintf(stderr, "final fit  %d / %d simulations\n", session.simulations() - before, budget);
  }
  const FitUpdate final_fit = running.get();
  if (progress) {
    std::fprintf(stderr,
                 "final fit: %d simulations in %.1f s wall (%d candidate answers checked from "
                 "the safe drop heights, %d rejected as unsafe)\n",
                 final_fit.evaluations, final_fit.wall_time_s, final_fit.safety_checks,
                 final_fit.rejected_unsafe);
  }
  emit(final_fit);
  return final_fit;
}

}  // namespace bouncefit::cli
