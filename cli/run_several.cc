// `bouncefit run a.mp4 b.mp4 ...`: several clips of one ball, each run on its
// own, their drops fitted jointly, and each drop written beside its simulation.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include "cli/fit_print.h"
#include "cli/run_options.h"
#include "pipeline/fit_stage.h"
#include "pipeline/message_mapping.h"
#include "pipeline/output_dir.h"
#include "fit/fit_export.h"
#include "model/model_by_name.h"
#include "msgs/msg_json.h"
#include "pipeline/offline_fit.h"
#include "report/report_run_data.h"

namespace bouncefit::cli {
namespace {

// Each drop of a joint fit beside the fitted ball dropped from its start apex: each clip's
// simulated.csv (its drops, so `report CLIPDIR` draws them, the paper's Fig. 7) and, for all
// drops, OUT/drops.csv (clip, start height, each fitted bounce by its number in the clip's
// peaks.csv with its recorded and simulated heights, as coefficients.json's drops hold them).
// order: each drop's place among all drops read (clip by clip). Returns each drop's clock
// against the simulation (run seconds per real second), in fitted's order.
std::vector<double> WriteDropsBesideTheirSimulation(const RunOptions& o, const BallPreset& ball, const FitUpdate& fit,
                                                    const std::vector<FitDrop>& fitted, const std::vector<size_t>& order,
                                                    const std::filesystem::path& root) {
  auto model = MakeBallModel(fit.model, ball);
  std::vector<size_t> by_order(fitted.size());
  for (size_t k = 0; k < by_order.size(); ++k) by_order[k] = k;
  std::sort(by_order.begin(), by_order.end(), [&](size_t a, size_t b) { return order[a] < order[b]; });
  std::vector<double> clocks(fitted.size(), 1.0);
  // One simulated.csv per clip, with every drop of it that was fitted.
  std::map<std::string, std::vector<size_t>> of_clip;
  for (size_t k : by_order) of_clip[fitted[k].clip].push_back(k);
  for (const auto& [clip, ks] : of_clip) {
    std::vector<FitDrop> its;
    for (size_t k : ks) its.push_back(fitted[k]);
    std::vector<double> ends(its.size(), INFINITY);  // each drop until the next one starts
    for (size_t i = 0; i + 1 < its.size(); ++i) ends[i] = its[i + 1].start_t_s;
    double run_s_per_real_s = 1;
    const auto simulated = SimulateFitDrops(*model, fit, its, ends, ball.chatter_hop_m(), &run_s_per_real_s);
    if (simulated.size() < its.size() && !o.quiet)
      std::fprintf(stderr, "run: warning: %s: the fitted ball diverges dropped from a start apex\n", clip.c_str());
    if (!simulated.empty()) WriteSimulatedCsv(root / clip, simulated, run_s_per_real_s);
    for (size_t k : ks) clocks[k] = run_s_per_real_s;
  }
  std::ofstream table(root / "drops.csv", std::ios::trunc);
  table << "drop,clip_dir,release_m,bounce,recorded_m,simulated_m\n";
  for (size_t n = 0; n < by_order.size(); ++n) {
    const FitDrop& d = fitted[by_order[n]];
    for (size_t i = 0; i < d.bounces.size(); ++i)
      table << fmt::format("{},{},{:.5f},{},{:.5f},{}\n", n + 1, d.clip, d.start_height_m, d.bounces[i], d.recorded_m[i],
                           std::isfinite(d.simulated_m[i]) ? fmt::format("{:.5f}", d.simulated_m[i]) : "");
  }
  return clocks;
}

// The tracked ball of a clip's run directory from its drop's start apex, in real seconds since
// it (the .glb's recorded_ball); empty without a calibration.
RecordedTrack RecordedFromRunDir(const std::filesystem::path& dir, const FitDrop& d, double run_s_per_real_s) {
  RecordedTrack r;
  const ReportRunData run = LoadRunDirectory(dir);
  if (!run.calibration || !run.calibration->usable() || !std::isfinite(d.start_t_s)) return r;
  for (const ReportTrackRow& row : run.track) {
    const double h = BallBottomHeightM(row, *run.calibration);
    if (row.t_s < d.start_t_s || !std::isfinite(h)) continue;
    r.t_s.push_back((row.t_s - d.start_t_s) / run_s_per_real_s);
    r.bottom_height_m.push_back(h);
  }
  return r;
}

}  // namespace

// Several clips of one ball: each run as `run CLIP --no-fit` into
// OUT/<k>-<name>/ (track, detect, sound, its own peaks), then every drop of every clip fitted
// jointly (the last one with the earlier ones) into OUT/coefficients.json and OUT/fitted_ball/.
ExitStatus RunSeveral(RunOptions o) {
  if (o.pick_window)
    throw std::invalid_argument("--pick-window picks on one clip: give --pick or --color, or run the clips one at a time");
  const BallPreset ball = ResolveBall(o.ball);
  const bool talk = !o.quiet && !o.json;
  const std::filesystem::path root(o.out);
  ClaimOutputDir(root, {"coefficients.json", "fitted_ball", "fitted_ball.glb", "drops.csv", "summary.json"}, o.overwrite);
  bool any_bounce = false;
  std::vector<std::vector<PeakInput>> drops;
  std::vector<std::filesystem::path> drop_dirs;  // the clip directory of each drop
  std::vector<int> clip_drops;                   // and its number there (peaks.csv's drop)
  nlohmann::json clips = nlohmann::json::array();
  for (size_t k = 0; k < o.clips.size(); ++k) {
    RunOptions one = o;
    one.clips = {o.clips[k]};
    one.no_fit = true;
    one.out = (root / (std::to_string(k + 1) + "-" + std::filesystem::path(o.clips[k]).stem().string())).string();
    if (talk) std::printf("run: clip %zu of %zu: %s -> %s\n", k + 1, o.clips.size(), o.clips[k].c_str(), one.out.c_str());
    std::fflush(stdout);
    nlohmann::json entry = {{"input", o.clips[k]}, {"out", one.out}};
    try {
      const ExitStatus status = RunOneClip(one, &ball);
      if (status == kExitInterrupted) return status;
      if (status == kExitNoBounce) throw std::runtime_error("no bounce found");
      any_bounce = true;
      // Every drop of the clip, each numbered as its peaks.csv does.
      std::vector<int> numbers;
      const auto its = ReadPeaksDrops(std::filesystem::path(one.out) / "peaks.csv", &numbers);
      size_t rebounds = 0;
      for (size_t d = 0; d < its.size(); ++d) {
        drops.push_back(its[d]);
        drop_dirs.push_back(one.out);
        clip_drops.push_back(numbers[d]);
        rebounds += its[d].size() - 1;
      }
      entry["release_m"] = its.front().front().height_m;
      entry["drops"] = its.size();
      entry["bounces"] = rebounds;
    } catch (const std::exception& e) {  // what that clip recorded stays in its directory
      if (!o.quiet) std::fprintf(stderr, "run: warning: %s: %s; not fitted\n", o.clips[k].c_str(), e.what());
      entry["not_fitted"] = e.what();
    }
    clips.push_back(entry);
  }
  nlohmann::json summary = {{"clips", clips}, {"ball", {{"name", ball.name}, {"diameter_m", ball.diameter_m}, {"mass_kg", ball.mass_kg}}}};
  if (!o.no_fit) {
    if (drops.empty()) {
      std::fprintf(stderr, "bouncefit run: no fit: no clip gave a drop with an apex and a rebound after it (see the warnings above)\n");
      std::ofstream(root / "summary.json") << summary.dump(2) << "\n";
      return any_bounce ? kExitNoFit : kExitNoBounce;
    }
    if (talk) std::printf("run: fitting the %zu drops jointly\n", drops.size());
    std::vector<std::pair<size_t, int>> fitted_drops;  // (clip's drop, the bounce its fit started from)
    const FitUpdate final_fit = FitDropsOffline(drops, FitConfig(o, ball), /*final_only=*/true, [&](const FitUpdate& u) {
      if (o.json)
        std::printf("%s\n", nlohmann::json{{"event", "fit"}, {"fit", ToJson(ToFitUpdateMsg(u), 0)}}.dump().c_str());
      else if (talk && u.final)
        PrintFitUpdate(u);
      std::fflush(stdout);
    }, [&](int sims, int budget) {
      if (talk) std::fprintf(stderr, "final fit  %d / %d simulations\n", sims, budget);
    }, &fitted_drops);
    if (!final_fit.no_answer.empty()) {
      std::fprintf(stderr, "bouncefit run: no fit: %s\n", final_fit.no_answer.c_str());
      summary["no_fit"] = final_fit.no_answer;
      std::ofstream(root / "summary.json") << summary.dump(2) << "\n";
      return kExitNoFit;
    }
    // Each drop on its clip's timeline, numbered as its peaks.csv does.
    std::vector<FitDrop> fitted = OfflineFitDrops(final_fit, drops, fitted_drops);
    std::vector<size_t> order(fitted.size());
    for (size_t k = 0; k < fitted.size(); ++k) {
      order[k] = static_cast<size_t>(fitted[k].drop);
      fitted[k].clip = drop_dirs.at(order[k]).filename().string();
      fitted[k].drop = clip_drops.at(order[k]);
    }
    const std::vector<double> clocks = WriteDropsBesideTheirSimulation(o, ball, final_fit, fitted, order, root);
    RecordedTrack recorded;
    if (!fitted.empty()) recorded = RecordedFromRunDir(root / fitted.front().clip, fitted.front(), clocks.front());
    FitExportContext context{"", "run", recorded.t_s.empty() ? nullptr : &recorded};
    context.drops = &fitted;
    context.run_s_per_real_s = clocks.empty() ? 1 : clocks.front();
    WriteFitExports(root, final_fit, ball, context);
    summary["final_fit"] = FitUpdateToJson(final_fit, ball);
  }
  std::ofstream(root / "summary.json") << summary.dump(2) << "\n";
  if (talk) std::printf("run: done: %zu clips, %zu drops fitted; wrote %s\n", o.clips.size(), drops.size(), root.string().c_str());
  return drops.empty() ? (any_bounce ? kExitAnswer : kExitNoBounce) : kExitAnswer;
}

}  // namespace bouncefit::cli
