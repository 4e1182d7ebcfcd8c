// bouncefit fit: the fit node (BOUNCE_PEAK in, FIT_UPDATE out) or, with --heights or
// --peaks, an offline fit of recorded bounce heights without video or LCM.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "cli/ball_flags.h"
#include "cli/bus_flags.h"
#include "cli/commands.h"
#include "cli/fit_print.h"
#include "cli/output_flags.h"
#include "cli/stop_signal.h"
#include "fit/fit_export.h"
#include "fit/fit_models.h"
#include "pipeline/exit_status.h"
#include "pipeline/fit_stage.h"
#include "pipeline/message_mapping.h"
#include "pipeline/output_dir.h"
#include "model/model_by_name.h"
#include "model/point_mass_model.h"
#include "msgs/lcm_bus.h"
#include "msgs/msg_json.h"

namespace bouncefit::cli {

namespace {

struct FitOptions {
  std::string heights;
  std::vector<std::string> peaks_csv;  // one file per drop, fitted jointly
  std::string export_dir;
  bool json = false;
  bool final_only = false;
  double final_after_s = 0;
  double duration_s = 0;
  bool exit_after_final = false;
  double exit_after_idle_s = 0;
  std::string out;
  bool overwrite = false;
  std::string lcm_url = kDefaultLcmUrl;
  BallFlags ball;
  FitSetup fit;  // its ball resolved from `ball` when the command runs
  Channels channels;
  int max_evals = 0;
  int max_evals_bounce = 0;
};

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
  if (o->max_evals > 0) o->fit.session.max_evaluations_final = o->max_evals;
  if (o->max_evals_bounce > 0) o->fit.session.max_evaluations_per_bounce = o->max_evals_bounce;
}

ExitStatus RunOffline(FitOptions o) {
  // Drops, each a list of peaks: --heights, or one per --peaks file (read before any fit,
  // so a bad file fails at once).
  std::vector<std::vector<PeakInput>> drops;
  if (!o.heights.empty()) {
    const auto h = ParseHeights(o.heights);
    drops.emplace_back();
    for (size_t i = 0; i < h.size(); ++i) drops.back().push_back({0, static_cast<int>(i), h[i], 0, 0});
  } else {
    for (const auto& path : o.peaks_csv)
      for (auto& drop : ReadPeaksDrops(path)) drops.push_back(std::move(drop));
  }
  const BallPreset& ball = o.fit.ball;
  std::vector<std::pair<size_t, int>> fitted;
  const FitUpdate final_fit = FitDropsOffline(
      drops, o.fit, o.final_only, [&](const FitUpdate& u) { Emit(o, ToFitUpdateMsg(u), u); },
      [](int sims, int budget) { std::fprintf(stderr, "final fit  %d / %d simulations\n", sims, budget); }, &fitted);
  if (!final_fit.no_answer.empty()) {
    std::fprintf(stderr, "bouncefit fit: no fit: %s\n", final_fit.no_answer.c_str());
    return kExitNoFit;
  }
  if (!o.export_dir.empty()) {
    const std::vector<FitDrop> timeline = OfflineFitDrops(final_fit, drops, fitted);
    FitExportContext context;
    context.fitted_by = "fit";
    context.drops = &timeline;
    for (const auto& path : WriteFitExports(o.export_dir, final_fit, ball, context))
      std::fprintf(stderr, "wrote %s\n", path.string().c_str());
  }
  return kExitAnswer;
}

ExitStatus RunNode(FitOptions o) {
  LcmBus bus(o.lcm_url);
  FitStageConfig fc;
  fc.fit = o.fit;
  fc.channels = o.channels;
  fc.final_after_s = o.final_after_s;
  if (!o.out.empty()) {
    ClaimOutputDir(o.out, FitOutputFiles(), o.overwrite);
    fc.out_dir = o.out;
  }
  FitStage stage(fc, bus, [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); });
  stage.set_update_observer([&](const fit_update_t& m, const FitUpdate& u) { Emit(o, m, u); });
  const std::atomic<bool>& stop = StopOnSignal();
  std::fprintf(stderr, "fit: %s model for %s, method %s; listening on %s (%s -> %s)\n", o.fit.model.c_str(),
               stage.ball().name.c_str(), o.fit.session.method.c_str(), o.lcm_url.c_str(),
               o.channels.bounce_peak.c_str(), o.channels.fit_update.c_str());
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto last_activity = Clock::now();
  int64_t last_message = 0;
  while (!stop && !stage.done()) {
    bus.HandleOnce(50);
    stage.Poll();
    if (o.exit_after_final && stage.final_fit()) break;
    if (stage.last_message_wall_us() != last_message || stage.busy()) {
      last_message = stage.last_message_wall_us();
      last_activity = Clock::now();
    }
    const double idle = std::chrono::duration<double>(Clock::now() - last_activity).count();
    if (o.exit_after_idle_s > 0 && idle > o.exit_after_idle_s) break;
    if (o.duration_s > 0 && std::chrono::duration<double>(Clock::now() - t0).count() > o.duration_s) break;
  }
  stage.Stop();
  stage.Poll();
  if (!o.export_dir.empty() && stage.final_fit())
    for (const auto& path : WriteFitExports(o.export_dir, *stage.final_fit(), stage.ball()))
      std::fprintf(stderr, "wrote %s\n", path.string().c_str());
  std::fprintf(stderr, "fit: %s%s\n", stage.final_fit() ? "final fit written" : "no final fit",
               o.out.empty() ? "" : (" into " + o.out).c_str());
  if (stop) return kExitInterrupted;
  return stage.final_fit() ? kExitAnswer : kExitNoFit;
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
  AddBallFlags(cmd, &o->ball);
  cmd->add_option("--model", o->fit.model, "model fitted: " + BallModelNames())
      ->capture_default_str();
  cmd->add_option("--method", o->fit.session.method,
                  "search: nlopt (BOBYQA, parallel screening) or paper (the seed's serial search)")
      ->check(CLI::IsMember({"nlopt", "paper"}))
      ->capture_default_str();
  cmd->add_option("--objective", o->fit.session.objective,
                  "segments (every bounce from the recorded apex before it: multiple shooting) "
                  "or drop (one free-running drop, the paper's)")
      ->check(CLI::IsMember({"segments", "drop"}))
      ->capture_default_str();
  cmd->add_option("--impact", o->fit.session.impact,
                  "the rebound: restitution (the law e(v) = e0 - k v, fitted in two stages) or "
                  "boost (the paper's extra force on Bullet's own rebound); docs/MODEL.md")
      ->check(CLI::IsMember({"restitution", "boost"}))
      ->capture_default_str();
  cmd->add_option("--flight-weight", o->fit.session.flight_weight_mps,
                  "weight of the flight times (impact to impact) in the objective, m/s (0: heights only)")
      ->capture_default_str();
  cmd->add_option("--max-evals", o->max_evals, "simulations for the final fit (default " +
                                                   std::to_string(o->fit.session.max_evaluations_final) + ")");
  cmd->add_option("--max-evals-bounce", o->max_evals_bounce,
                  "simulations for each per-bounce update (default " +
                      std::to_string(o->fit.session.max_evaluations_per_bounce) + ")");
  cmd->add_option("--threads", o->fit.session.threads, "parallel simulations (0: all cores)")
      ->capture_default_str();
  cmd->add_option("--min-bounce", o->fit.session.min_bounce_height_m,
                  "bounces lower than this are not fitted, m")
      ->capture_default_str();
  cmd->add_option("--export", o->export_dir,
                  "write the final fit to DIR/coefficients.json and DIR/fitted_ball/ (a CMake project: "
                  "the fitted ball for Bullet, program fitted_ball H)");
  cmd->add_flag("--json", o->json, "print updates as JSON lines (fit_update_t fields)");
  cmd->add_flag("--final-only", o->final_only, "offline: only the quick and the final fit");
  AddBusFlags(cmd, &o->lcm_url, &o->channels);
  cmd->add_option("--final-after", o->final_after_s,
                  "node: final fit of a drop after this many seconds without a peak, for logs without DROP (0: never)")
      ->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "node: stop after this many seconds (0: run until Ctrl-C)");
  cmd->add_flag("--exit-after-final", o->exit_after_final, "node: stop after the first final fit");
  cmd->add_option("--exit-after-idle", o->exit_after_idle_s,
                  "node: exit when nothing came and nothing was fitted for this many seconds (0: never)");
  AddOutputFlags(cmd, &o->out, &o->overwrite,
                 "fit.jsonl and, when the stream is done, coefficients.json, fitted_ball/ and simulated.csv");
  cmd->footer("Examples:\n"
              "  bouncefit fit --ball tennis --out out/drop --exit-after-idle 5     # the fit node\n"
              "  bouncefit fit --heights 1.0,0.62,0.40 --ball pingpong                # offline\n"
              "  bouncefit fit --peaks a/peaks.csv --peaks b/peaks.csv --ball tennis --export out/fit\n"
              "Exit status: 0 a final fit, 1 an error, 2 a bad flag, 4 no fit, 130 stopped.");
  cmd->callback([o] {
    o->fit.ball = ResolveBall(o->ball);
    ApplyBudgets(o.get());
    const ExitStatus status = !o->heights.empty() || !o->peaks_csv.empty() ? RunOffline(*o) : RunNode(*o);
    if (status != kExitAnswer) throw CLI::RuntimeError(static_cast<int>(status));
  });
}

}  // namespace bouncefit::cli
