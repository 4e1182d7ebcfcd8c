// `bouncefit run a.mp4 b.mp4 ...`: several clips of one ball, each run on its
// own, their drops fitted jointly, and each drop written beside its simulation.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli/fit_print.h"
#include "cli/run_options.h"
#include "pipeline/fit_stage.h"
#include "pipeline/output_dir.h"
#include "fit/fit_export.h"
#include "model/model_by_name.h"
#include "msgs/msg_json.h"

namespace bouncefit::cli {
namespace {

std::string Fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// Each drop of a joint fit beside the fitted ball dropped from its release: the clip's
// simulated.csv (so `report CLIPDIR` draws it, the paper's Fig. 7) and, for all drops,
// OUT/drops.csv (clip, release, bounce, recorded and simulated heights).
void WriteDropsBesideTheirSimulation(const RunOptions& o, const BallPreset& ball, const FitUpdate& fit,
                                     const std::vector<std::vector<PeakInput>>& drops,
                                     const std::vector<std::filesystem::path>& dirs,
                                     const std::filesystem::path& root) {
  auto model = MakeBallModel(fit.model, ball);
  std::ofstream table(root / "drops.csv", std::ios::trunc);
  table << "drop,clip_dir,release_m,bounce,recorded_m,simulated_m\n";
  for (size_t d = 0; d < drops.size(); ++d) {
    SimulationOptions so;
    so.drop_height_m = drops[d].front().height_m;
    so.record_trajectory = true;
    so.duration_s = 8.0;
    const SimulationResult r = model->Simulate(fit.values, so);
    if (!r.ok) {
      if (!o.quiet) std::fprintf(stderr, "run: warning: the fitted ball dropped from %.3f m: %s\n",
                                 so.drop_height_m, r.failure.c_str());
      continue;
    }
    WriteSimulatedCsv(dirs[d], static_cast<double>(drops[d].front().utime) * 1e-6, r.trajectory);
    for (size_t i = 1; i < drops[d].size(); ++i) {
      const size_t b = static_cast<size_t>(drops[d][i].bounce);
      table << d + 1 << ',' << dirs[d].filename().string() << ',' << Fixed(so.drop_height_m, 5) << ','
            << b << ',' << Fixed(drops[d][i].height_m, 5) << ','
            << (b >= 1 && b <= r.bounce_heights_m.size() ? Fixed(r.bounce_heights_m[b - 1], 5) : "") << '\n';
    }
  }
}

}  // namespace

// Several clips of one ball: each run as `run CLIP --no-fit` into
// OUT/<k>-<name>/ (track, detect, sound, its own peaks), then the drops fitted jointly, the last
// clip's drop with the earlier ones, into OUT/coefficients.json and OUT/fitted_ball/.
ExitStatus RunSeveral(RunOptions o) {
  if (o.pick_window)
    throw std::invalid_argument("--pick-window picks on one clip: give --pick or --color, or run the clips one at a time");
  if (o.ball.empty()) o.ball = "pingpong";
  const BallPreset ball = ResolveBallPreset(o.ball, o.diameter_m, o.mass_kg);  // validates it
  const bool talk = !o.quiet && !o.json;
  const std::filesystem::path root(o.out);
  ClaimOutputDir(root, {"coefficients.json", "fitted_ball", "fitted_ball.glb", "drops.csv", "summary.json"}, o.overwrite);
  bool any_bounce = false;
  std::vector<std::vector<PeakInput>> drops;
  std::vector<std::filesystem::path> fitted_dirs;  // the clip directory of each drop
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
      const ExitStatus status = RunOneClip(one);
      if (status == kExitInterrupted) return status;
      if (status == kExitNoBounce) throw std::runtime_error("no bounce found");
      any_bounce = true;
      drops.push_back(ReadDropPeaks(std::filesystem::path(one.out) / "peaks.csv"));
      fitted_dirs.push_back(one.out);
      entry["release_m"] = drops.back().front().height_m;
      entry["bounces"] = drops.back().size() - 1;
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
    const FitUpdate final_fit = FitDropsOffline(drops, FitConfig(o), /*final_only=*/true, [&](const FitUpdate& u) {
      if (o.json)
        std::printf("%s\n", nlohmann::json{{"event", "fit"}, {"fit", ToJson(FitNode::ToMessage(u), 0)}}.dump().c_str());
      else if (talk && u.final)
        PrintFitUpdate(u);
      std::fflush(stdout);
    }, [&](int sims, int budget) {
      if (talk) std::fprintf(stderr, "final fit  %d / %d simulations\n", sims, budget);
    });
    if (!final_fit.no_answer.empty()) {
      std::fprintf(stderr, "bouncefit run: no fit: %s\n", final_fit.no_answer.c_str());
      summary["no_fit"] = final_fit.no_answer;
      std::ofstream(root / "summary.json") << summary.dump(2) << "\n";
      return kExitNoFit;
    }
    WriteFitExports(root, final_fit, ball);
    summary["final_fit"] = FitUpdateToJson(final_fit, ball);
    WriteDropsBesideTheirSimulation(o, ball, final_fit, drops, fitted_dirs, root);
  }
  std::ofstream(root / "summary.json") << summary.dump(2) << "\n";
  if (talk) std::printf("run: done: %zu clips, %zu drops fitted; wrote %s\n", o.clips.size(), drops.size(), root.string().c_str());
  return drops.empty() ? (any_bounce ? kExitAnswer : kExitNoBounce) : kExitAnswer;
}

}  // namespace bouncefit::cli
