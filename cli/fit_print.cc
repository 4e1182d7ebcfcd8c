#include "cli/fit_print.h"

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

}  // namespace bouncefit::cli
