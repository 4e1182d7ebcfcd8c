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
#include "cli/fit_offline.h"
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

void Emit(const FitOptions& o, const fit_update_t& m, const FitUpdate& u) {
  if (o.json)
    std::printf("%s\n", ToJson(m, 0).dump().c_str()), std::fflush(stdout);
  else
    PrintFitUpdate(u);
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
  const BallPreset ball = ResolveBallPreset(o.node.ball, o.node.diameter_m, o.node.mass_kg);
  const FitUpdate final_fit = FitDropsOffline(drops, o.node, o.final_only,
                                              [&](const FitUpdate& u) { Emit(o, FitNode::ToMessage(u), u); });
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
