#include "cli/fit_print.h"

#include <fmt/format.h>

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

// A number the fit could not give (NaN: no uncertainty, no residual) prints as "n/a".
constexpr const char* kUnknown = "n/a";

}  // namespace

void PrintFitUpdate(const FitUpdate& u) {
  const double residual_mm = u.residual_m * 1000;
  fmt::print("{} fit after bounce {}  [{}, {}]: RMS residual {} mm over {} bounces, {} simulations, {:.2f} s{}\n",
             u.final ? "FINAL" : (u.model == "point-mass" ? "quick" : "bounce"), u.after_bounce, u.model, u.method,
             std::isfinite(residual_mm) ? fmt::format("{:.3g}", residual_mm) : kUnknown, u.recorded_m.size(),
             u.evaluations, u.wall_time_s, u.cancelled ? " (cut short)" : "");
  for (const auto& c : u.coefficients) {
    const std::string unit = c.unit.empty() ? "" : " " + c.unit;
    const std::string value = std::isfinite(c.value) ? fmt::format("{:.6g}", c.value) : kUnknown;
    if (c.identifiable)
      fmt::print("  {:<28} {:>12} +- {:<10}{}\n", c.name, value,
                 std::isfinite(c.sigma) ? fmt::format("{:.2g}", c.sigma) : kUnknown, unit);
    else
      fmt::print("  {:<28} {:>12} {}  ({})\n", c.name, value, unit, c.note.empty() ? "not identifiable" : c.note);
  }
  fmt::print("  recorded  (m):");
  for (double r : u.recorded_m) fmt::print(" {:.4f}", r);
  fmt::print("\n  simulated (m):");
  for (double s : u.simulated_m) fmt::print(" {:.4f}", s);
  fmt::print("\n");
  if (!u.other_drop_heights_m.empty()) {  // a joint fit: which bounces are which drop's
    size_t first = u.recorded_m.size();
    for (int n : u.other_drop_bounces) first -= static_cast<size_t>(n);
    fmt::print("  drops: {:.4f} m (bounces 1-{})", u.drop_height_m, first);
    size_t at = first;
    for (size_t d = 0; d < u.other_drop_heights_m.size(); ++d) {
      fmt::print(", {:.4f} m ({}-{})", u.other_drop_heights_m[d], at + 1,
                 at + static_cast<size_t>(u.other_drop_bounces[d]));
      at += static_cast<size_t>(u.other_drop_bounces[d]);
    }
    fmt::print("\n");
  }
  if (!u.segment_simulated_m.empty()) {
    fmt::print("  segments  (m):");  // bounce i from the recorded apex i-1
    for (double s : u.segment_simulated_m) fmt::print(" {:.4f}", s);
    const double rms_mm = u.segment_residual_m * 1000;
    fmt::print("   RMS {} mm\n", std::isfinite(rms_mm) ? fmt::format("{:.3g}", rms_mm) : kUnknown);
  }
  if (!u.free_run_mean_m.empty()) {
    fmt::print("  free drop, ensemble mean +- sd (m):");
    for (size_t i = 0; i < u.free_run_mean_m.size(); ++i)
      fmt::print(" {:.4f}+-{:.4f}", u.free_run_mean_m[i], u.free_run_sd_m[i]);
    const double rms_mm = u.free_run_residual_m * 1000;
    fmt::print("   RMS {} mm\n", std::isfinite(rms_mm) ? fmt::format("{:.3g}", rms_mm) : kUnknown);
  }
  if (!u.warning.empty()) fmt::print("  warning: {}\n", u.warning);
  if (u.time_step_s > 0) fmt::print("  holds for time step {:.6g} s, {} position iterations\n", u.time_step_s, u.iterations);
  std::fflush(stdout);
}

}  // namespace bouncefit::cli
