// bouncefit fit: the fit node (BOUNCE_PEAK in, FIT_UPDATE out) or, with --heights or
// --peaks, an offline fit of recorded bounce heights without video or LCM.
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "cli/bus_flags.h"
#include "cli/commands.h"
#include "fit/fit_export.h"
#include "fit/fit_models.h"
#include "fit/node/fit_node.h"
#include "model/model_by_name.h"
#include "model/point_mass_model.h"
#include "msgs/msg_json.h"

namespace bouncefit::cli {

namespace {

struct FitOptions {
  std::string heights;
  std::vector<std::string> peaks_csv;  // one file per drop, fitted jointly
  std::string export_dir;
  bool json = false;
  bool final_only = false;
  double final_after_s = 2.0;
  double duration_s = 0;
  bool exit_after_final = false;
  std::string lcm_url = kDefaultLcmUrl;
  FitNodeConfig node;
  int max_evals = 0;
  int max_evals_bounce = 0;
};

std::atomic<bool> g_interrupted{false};
void OnSignal(int) { g_interrupted = true; }

std::vector<double> ParseHeights(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    size_t used = 0;
    double h = 0;
    try {
      h = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || !std::isfinite(h) || h < 0)
      throw std::invalid_argument("--heights: '" + item + "' is not a height in metres");
    v.push_back(h);
  }
  if (v.size() < 2)
    throw std::invalid_argument("--heights needs the drop height and at least one bounce");
  return v;
}

// peaks.csv (docs/FORMATS.md): columns by header name; rows of bounce 0 start a new drop,
// only the first drop is fitted.
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
  const int ib = index("bounce"), ih = index("height_m"), it = index("t_s");
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
      p.height_m = std::stod(cells[ih]);
      if (it >= 0 && it < static_cast<int>(cells.size()) && !cells[it].empty())
        p.utime = static_cast<int64_t>(std::llround(std::stod(cells[it]) * 1e6));
    } catch (const std::exception&) {
      throw std::runtime_error(path + ":" + std::to_string(row) + ": not a number");
    }
    if (p.bounce == 0 && ++drops > 1) break;
    peaks.push_back(p);
  }
  if (peaks.empty() || peaks.front().bounce != 0)
    throw std::runtime_error(path + ": the first peak must be bounce 0 (the release height)");
  return peaks;
}

std::string Fmt(double v, int digits = 4) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

void PrintUpdate(const FitUpdate& u) {
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

void Emit(const FitOptions& o, const fit_update_t& m, const FitUpdate& u) {
  if (o.json)
    std::printf("%s\n", ToJson(m, 0).dump().c_str()), std::fflush(stdout);
  else
    PrintUpdate(u);
}

void ApplyBudgets(FitOptions* o) {
  if (o->max_evals > 0) o->node.session.max_evaluations_final = o->max_evals;
  if (o->max_evals_bounce > 0) o->node.session.max_evaluations_per_bounce = o->max_evals_bounce;
}

void RunOffline(FitOptions o) {
  // Drops, each a list of peaks: --heights, or one per --peaks file (read before any fit,
  // so a bad file fails at once).
  std::vector<std::vector<PeakInput>> drops;
  if (!o.heights.empty()) {
    const auto h = ParseHeights(o.heights);
    drops.emplace_back();
    for (size_t i = 0; i < h.size(); ++i) drops.back().push_back({0, static_cast<int>(i), h[i], 0, 0});
  } else {
    for (const auto& path : o.peaks_csv) drops.push_back(ReadPeaksCsv(path));
  }
  for (size_t d = 0; d < drops.size(); ++d)
    for (auto& p : drops[d]) p.sequence = static_cast<int>(d);
  const BallPreset ball = ResolveBallPreset(o.node.ball, o.node.diameter_m, o.node.mass_kg);
  auto model = MakeBallModel(o.node.model, ball);
  PointMassModel quick(ball);
  ConfigureSessionForModel(*model, ball, &o.node.session);
  FitSession session(*model, &quick, o.node.session);
  auto emit = [&](const FitUpdate& u) { Emit(o, FitNode::ToMessage(u), u); };
  // As the node would: the point-mass estimate and a refinement after every bounce (no
  // newer peak ever supersedes them offline), then the final fit.
  // Earlier drops are kept and fitted with the last one (issue 14 item 4).
  for (size_t d = 0; d < drops.size(); ++d) {
    if (d > 0) session.KeepDropAndReset(static_cast<int>(d));
    for (const auto& p : drops[d]) {
      session.AddPeak(p);
      if (o.final_only || p.bounce < 1 || !session.CanFit()) continue;
      if (static_cast<int>(session.FittedHeights().size()) < p.bounce) continue;  // below 1 cm
      emit(session.QuickUpdate());
      emit(session.Update());
    }
  }
  if (!session.CanFit())
    throw std::runtime_error("no bounce above " +
                             Fmt(o.node.session.min_bounce_height_m * 100, 3) + " cm to fit");
  if (o.final_only) emit(session.QuickUpdate());
  // The final fit takes seconds: its progress on stderr (stdout carries the updates).
  auto running = std::async(std::launch::async, [&session] { return session.FinalUpdate(); });
  const int budget = session.FinalBudget();
  const int before = session.simulations();
  while (running.wait_for(std::chrono::seconds(1)) != std::future_status::ready)
    std::fprintf(stderr, "final fit  %d / %d simulations\n", session.simulations() - before,
                 budget);
  const FitUpdate final_fit = running.get();
  std::fprintf(stderr,
               "final fit: %d simulations in %.1f s wall (%d candidate answers checked from "
               "the safe drop heights, %d rejected as unsafe)\n",
               final_fit.evaluations, final_fit.wall_time_s, final_fit.safety_checks,
               final_fit.rejected_unsafe);
  emit(final_fit);
  if (!o.export_dir.empty()) {
    for (const auto& path : WriteFitExports(o.export_dir, final_fit, ball))
      std::fprintf(stderr, "wrote %s\n", path.string().c_str());
  }
}

void RunNode(FitOptions o) {
  LcmBus bus(o.lcm_url);
  std::atomic<bool> final_seen{false};
  BallPreset ball;
  std::mutex last_final_mutex;
  FitUpdate last_final;
  bool have_final = false;
  FitNode node(o.node, [&](const fit_update_t& m, const FitUpdate& u) {
    Emit(o, m, u);
    if (u.final) {
      std::lock_guard<std::mutex> lock(last_final_mutex);
      last_final = u;
      have_final = true;
      final_seen = true;
    }
  });
  ball = node.ball();
  node.Attach(&bus);
  node.Start();
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::fprintf(stderr, "fit: %s model for %s, method %s; listening on %s (%s -> %s)\n",
               node.model().name().c_str(), ball.name.c_str(), o.node.session.method.c_str(),
               o.lcm_url.c_str(), o.node.channels.bounce_peak.c_str(),
               o.node.channels.fit_update.c_str());
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto last_peak_seen = Clock::now();
  int64_t last_peak_utime = 0;
  bool finished = true;  // nothing to finish until a peak arrives
  while (!g_interrupted) {
    bus.HandleOnce(50);
    const int64_t u = node.last_peak_utime();
    if (u != last_peak_utime) {
      last_peak_utime = u;
      last_peak_seen = Clock::now();
      finished = false;
    }
    // A drop is over when no peak has come for a while: its final fit.
    if (!finished && o.final_after_s > 0 &&
        std::chrono::duration<double>(Clock::now() - last_peak_seen).count() > o.final_after_s) {
      node.Finish();
      finished = true;
    }
    if (o.exit_after_final && final_seen) break;
    if (o.duration_s > 0 &&
        std::chrono::duration<double>(Clock::now() - t0).count() > o.duration_s)
      break;
  }
  node.Stop();
  if (!o.export_dir.empty()) {
    std::lock_guard<std::mutex> lock(last_final_mutex);
    if (have_final)
      for (const auto& path : WriteFitExports(o.export_dir, last_final, ball))
        std::fprintf(stderr, "wrote %s\n", path.string().c_str());
  }
  const auto s = node.stats();
  std::fprintf(stderr, "fit: %d peaks, %d updates, %d superseded, %d final\n", s.peaks,
               s.updates_delivered, s.superseded, s.finals);
}

}  // namespace

void AddFitCommand(CLI::App& app) {
  auto o = std::make_shared<FitOptions>();
  auto* cmd = app.add_subcommand(
      "fit",
      "Fit a soft-body ball model after every bounce; publish FIT_UPDATE (or fit recorded "
      "heights offline with --heights / --peaks)");
  cmd->add_option("--heights", o->heights,
                  "offline: drop height then bounce apex heights, metres, e.g. 1.0,0.62,0.40");
  cmd->add_option("--peaks", o->peaks_csv,
                  "offline: a peaks.csv (docs/FORMATS.md); repeat it for several drops of the "
                  "same ball, fitted jointly")
      ->check(CLI::ExistingFile)
      ->excludes(cmd->get_option("--heights"));
  cmd->add_option("--ball", o->node.ball, "ball preset (" + BallPresetNames() + ")")
      ->capture_default_str();
  cmd->add_option("--mass", o->node.mass_kg, "ball mass, kg (overrides the preset)");
  cmd->add_option("--diameter", o->node.diameter_m, "ball diameter, m (overrides the preset)");
  cmd->add_option("--model", o->node.model, "model fitted: " + BallModelNames())
      ->capture_default_str();
  cmd->add_option("--method", o->node.session.method,
                  "search: nlopt (BOBYQA, parallel screening) or paper (the seed's serial search)")
      ->check(CLI::IsMember({"nlopt", "paper"}))
      ->capture_default_str();
  cmd->add_option("--objective", o->node.session.objective,
                  "segments (every bounce from the recorded apex before it: multiple shooting) "
                  "or drop (one free-running drop, the paper's)")
      ->check(CLI::IsMember({"segments", "drop"}))
      ->capture_default_str();
  cmd->add_option("--impact", o->node.session.impact,
                  "the rebound: restitution (the law e(v) = e0 - k v, fitted in two stages) or "
                  "boost (the paper's extra force on Bullet's own rebound); docs/MODEL.md")
      ->check(CLI::IsMember({"restitution", "boost"}))
      ->capture_default_str();
  cmd->add_option("--flight-weight", o->node.session.flight_weight_mps,
                  "weight of the flight times (impact to impact) in the objective, m/s (0: heights only)")
      ->capture_default_str();
  cmd->add_option("--max-evals", o->max_evals, "simulations for the final fit (default " +
                                                   std::to_string(o->node.session.max_evaluations_final) + ")");
  cmd->add_option("--max-evals-bounce", o->max_evals_bounce,
                  "simulations for each per-bounce update (default " +
                      std::to_string(o->node.session.max_evaluations_per_bounce) + ")");
  cmd->add_option("--threads", o->node.session.threads, "parallel simulations (0: all cores)")
      ->capture_default_str();
  cmd->add_option("--min-bounce", o->node.session.min_bounce_height_m,
                  "bounces lower than this are not fitted, m")
      ->capture_default_str();
  cmd->add_option("--export", o->export_dir,
                  "write the final fit to DIR/coefficients.json and DIR/fitted_ball/ (a CMake project: "
                  "the fitted ball for Bullet, program fitted_ball H)");
  cmd->add_flag("--json", o->json, "print updates as JSON lines (fit_update_t fields)");
  cmd->add_flag("--final-only", o->final_only, "offline: only the quick and the final fit");
  AddBusFlags(cmd, &o->lcm_url, &o->node.channels);
  cmd->add_option("--final-after", o->final_after_s,
                  "node: final fit of a drop after this many seconds without a peak (0: never)")
      ->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "node: stop after this many seconds (0: run until Ctrl-C)");
  cmd->add_flag("--exit-after-final", o->exit_after_final, "node: stop after the first final fit");
  cmd->callback([o] {
    ApplyBudgets(o.get());
    if (!o->heights.empty() || !o->peaks_csv.empty())
      RunOffline(*o);
    else
      RunNode(*o);
  });
}

}  // namespace bouncefit::cli
