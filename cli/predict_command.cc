// bouncefit predict: the bounce heights a fitted ball is expected to reach when dropped from
// a given height, as the mean (and spread) of an ensemble of tiny perturbations of the release
// (fit/drop_ensemble.h), for either model; also the single unperturbed run, which is what
// `simulate` prints and what the fit reported at its own drop. --gltf also writes that
// single run as an animation (fit/fitted_ball_gltf.h). Without --drop, a run's
// coefficients.json is dropped from the apex its fit started from, its bounces named and
// timed as that run's peaks.csv names and times them.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/ball_flags.h"
#include "cli/commands.h"
#include "fit/drop_ensemble.h"
#include "fit/fit_export.h"
#include "fit/fitted_ball_gltf.h"
#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/model_by_name.h"
#include "model/soft_ball_model.h"

namespace bouncefit::cli {
namespace {

struct PredictOptions {
  std::string coeffs;
  double drop_m = 0;
  BallFlags ball;  // not given: the file's
  std::string gltf;  // "" = none; else the single run as a .glb
  bool json = false;
  double min_height_m = 0.01;
  double duration_s = 0;  // 0: long enough for bounces down to min_height_m
  DropEnsembleOptions ensemble;
};

// The fitted coefficients' uncertainty in a fit's coefficients.json: the covariance of the
// identifiable ones ("covariance": {"names", "matrix"}), else their sigmas alone
// ("coefficients": {name: {"value", "sigma"}}) as uncorrelated; none for a plain table.
struct FittedUncertainty {
  std::vector<std::string> names;
  std::vector<std::vector<double>> cov;
};

// Where a run's fit started (coefficients.json's drops: the fit's own drop first), so that the
// ball dropped from there is told on the run's timeline.
struct RunStart {
  bool known = false;
  int drop = 0, bounce = 0;      // the start apex in peaks.csv
  double t_s = std::nan(""), height_m = 0;
  double time_scale = 1;         // real seconds per second of the run's clock
  std::map<int, double> recorded_m;  // the fit's recorded height by bounce
};

RunStart ReadRunStart(const std::string& path) {
  RunStart r;
  try {
    const auto j = nlohmann::json::parse(std::ifstream(path));
    if (!j.contains("drops") || !j["drops"].is_array() || j["drops"].empty()) return r;
    const auto& d = j["drops"][0];
    r.drop = d.value("drop", 0);
    r.bounce = d.value("start_bounce", 0);
    r.t_s = d["start_t_s"].is_number() ? d["start_t_s"].get<double>() : std::nan("");
    r.height_m = d.value("start_height_m", 0.0);
    r.time_scale = j.value("time_scale", 1.0);
    const auto bounces = d.value("bounces", std::vector<int>());
    for (size_t i = 0; i < bounces.size() && i < d["recorded_m"].size(); ++i)
      if (d["recorded_m"][i].is_number()) r.recorded_m[bounces[i]] = d["recorded_m"][i].get<double>();
    r.known = r.height_m > 0 && r.time_scale > 0;
  } catch (const std::exception&) {
    r = {};
  }
  return r;
}

FittedUncertainty ReadUncertainty(const std::string& path) {
  FittedUncertainty out;
  try {
    std::ifstream f(path);
    const auto j = nlohmann::json::parse(f);
    if (j.contains("covariance") && j["covariance"].is_object() && !j["covariance"]["names"].empty()) {
      out.names = j["covariance"]["names"].get<std::vector<std::string>>();
      out.cov = j["covariance"]["matrix"].get<std::vector<std::vector<double>>>();
      if (out.cov.size() == out.names.size()) return out;
      out = {};
    }
    if (!j.contains("coefficients") || !j["coefficients"].is_object()) return out;
    for (const auto& [name, c] : j["coefficients"].items())
      if (c.is_object() && c.contains("sigma") && c["sigma"].is_number()) {
        const double s = c["sigma"].get<double>();
        if (std::isfinite(s) && s > 0) out.names.push_back(name);
      }
    out.cov.assign(out.names.size(), std::vector<double>(out.names.size(), 0.0));
    for (size_t i = 0; i < out.names.size(); ++i) {
      const double s = j["coefficients"][out.names[i]]["sigma"].get<double>();
      out.cov[i][i] = s * s;
    }
  } catch (const std::exception&) {
    out = {};
  }
  return out;
}

// Per bounce, the spread the coefficients' uncertainty gives, linearised: each coefficient
// moved by +- its sigma (within its bounds) in the unperturbed run gives the heights'
// gradient g, and the variance is g^T C g.
std::vector<double> ParameterSpread(const BallModel& model, const CoefficientValues& values,
                                    const FittedUncertainty& u, const SimulationOptions& drop, size_t bounces,
                                    int* runs) {
  const size_t n = u.names.size();
  std::vector<std::vector<double>> grad(n, std::vector<double>(bounces, 0.0));
  const auto specs = model.Coefficients();
  for (size_t j = 0; j < n; ++j) {
    auto spec = std::find_if(specs.begin(), specs.end(), [&](const auto& s) { return s.name == u.names[j]; });
    auto v = values.find(u.names[j]);
    const double sigma = std::sqrt(std::max(0.0, u.cov[j][j]));
    if (spec == specs.end() || v == values.end() || !(sigma > 0)) continue;
    CoefficientValues up = values, down = values;
    up[spec->name] = std::min(spec->upper, v->second + sigma);
    down[spec->name] = std::max(spec->lower, v->second - sigma);
    const double span = up[spec->name] - down[spec->name];
    if (!(span > 0)) continue;
    const SimulationResult a = model.Simulate(up, drop), b = model.Simulate(down, drop);
    *runs += 2;
    if (!a.ok || !b.ok) continue;
    for (size_t i = 0; i < bounces; ++i) {
      const double ha = i < a.bounce_heights_m.size() ? a.bounce_heights_m[i] : 0.0;
      const double hb = i < b.bounce_heights_m.size() ? b.bounce_heights_m[i] : 0.0;
      grad[j][i] = (ha - hb) / span;  // metres per unit of the coefficient
    }
  }
  std::vector<double> sd(bounces, 0.0);
  for (size_t i = 0; i < bounces; ++i) {
    double var = 0;
    for (size_t a = 0; a < n; ++a)
      for (size_t b = 0; b < n; ++b) var += grad[a][i] * u.cov[a][b] * grad[b][i];
    sd[i] = std::sqrt(std::max(0.0, var));
  }
  return sd;
}

void Run(PredictOptions o) {
  // No --drop: a run's own start apex, on its timeline.
  const RunStart run = o.drop_m == 0 ? ReadRunStart(o.coeffs) : RunStart{};
  if (o.drop_m == 0 && !run.known)
    throw std::invalid_argument("--drop is needed: " + o.coeffs + " says no start apex of a run");
  if (run.known) o.drop_m = run.height_m;
  if (!(o.drop_m > 0 && o.drop_m < 100)) throw std::invalid_argument("--drop must be in (0, 100) m");
  if (o.ensemble.members < 1 || o.ensemble.members > 1000)
    throw std::invalid_argument("--members must be 1..1000");
  if (!(o.min_height_m > 0)) throw std::invalid_argument("--min-height must be > 0 m");
  const CoefficientTable table = LoadCoefficientTable(o.coeffs);
  if (table.values.empty()) throw std::runtime_error(o.coeffs + ": no coefficients in it");
  if (o.ball.name.empty() && table.ball.empty())
    throw std::invalid_argument(o.coeffs + " does not name its ball: give --ball");
  const BallPreset ball =
      ResolveBall(o.ball, {table.ball, table.diameter_m.value_or(0), table.mass_kg.value_or(0)});
  const std::string model_name = table.model.empty() ? "bullet-softbody" : table.model;
  const auto model = MakeBallModel(model_name, ball);
  if (const auto* soft = dynamic_cast<const SoftBallModel*>(model.get())) {
    // The coefficients hold for one time step and iteration count only.
    if (table.time_step_s && std::abs(*table.time_step_s - soft->config().time_step_s) > 1e-12)
      throw std::runtime_error(o.coeffs + ": coefficients for another time step (" +
                               std::to_string(*table.time_step_s) + " s)");
    if (table.position_iterations &&
        *table.position_iterations != soft->config().position_iterations)
      throw std::runtime_error(o.coeffs + ": coefficients for another iteration count (" +
                               std::to_string(*table.position_iterations) + ")");
  }
  SimulationOptions drop;
  drop.drop_height_m = o.drop_m;
  drop.min_bounce_height_m = o.min_height_m;
  // A ball with restitution e needs ~ sqrt(2H/g)(1 + 2/(1-e)) s; 20 s covers e < 0.95 from 2 m.
  drop.duration_s = o.duration_s > 0 ? o.duration_s : 6 + 10 * std::sqrt(o.drop_m);
  const DropEnsemble e = SimulateDropEnsemble(*model, table.values, drop, o.ensemble);
  if (!e.ok)
    throw std::runtime_error("the ball diverges dropped from " + std::to_string(o.drop_m) +
                             " m (" + e.failure + ")");
  // The spread: the ensemble's (the model's own chaos) and the fitted coefficients' uncertainty.
  int param_runs = 0;
  const std::vector<double> param_sd =
      ParameterSpread(*model, table.values, ReadUncertainty(o.coeffs), drop, e.mean_m.size(), &param_runs);
  std::vector<double> sd(e.mean_m.size());
  for (size_t i = 0; i < sd.size(); ++i) sd[i] = std::hypot(e.sd_m[i], param_sd[i]);
  // On a run's timeline: each bounce's number and its single run's apex time in peaks.csv's.
  std::vector<int> numbers;
  std::vector<double> apex_t_s;
  if (run.known) {
    const SimulationResult single = model->Simulate(table.values, drop);
    for (size_t i = 0; i < e.mean_m.size(); ++i) {
      numbers.push_back(run.bounce + 1 + static_cast<int>(i));
      apex_t_s.push_back(i < single.apex_times_s.size() ? run.t_s + single.apex_times_s[i] / run.time_scale
                                                         : std::nan(""));
    }
  }
  if (!o.gltf.empty()) {
    FitUpdate fit;  // the extras say what the file says of its fit
    fit.model = model->name();
    fit.values = table.values;
    fit.drop_height_m = table.drop_height_m.value_or(0);
    fit.residual_m = std::nan("");
    FittedBallGltfOptions gltf_options;
    gltf_options.min_bounce_height_m = std::min(gltf_options.min_bounce_height_m, o.min_height_m);
    FitExportContext context{"", "predict --coeffs " + o.coeffs, nullptr};
    std::vector<FitDrop> start;  // a run's start apex: where the file's t = 0 is in the clip
    if (run.known) {
      start.push_back({});
      start.back().drop = run.drop;
      start.back().start_bounce = run.bounce;
      start.back().start_t_s = run.t_s;
      start.back().start_height_m = run.height_m;
      context.drops = &start;
      context.run_s_per_real_s = 1 / run.time_scale;
    }
    const FittedBallGltf g = WriteFittedBallGltf(o.gltf, *model, ball, table.values, o.drop_m,
                                                 FitGltfExtras(fit, ball, context), nullptr, gltf_options);
    std::fprintf(o.json ? stderr : stdout,
                 "wrote %s: %zu keys at %.0f per second (%.2f s), %zu morph targets, %zu bytes\n",
                 o.gltf.c_str(), g.keys, gltf_options.rate_hz,
                 g.keys ? double(g.keys - 1) / gltf_options.rate_hz : 0.0, g.morph_targets, g.bytes);
  }
  if (o.json) {
    nlohmann::ordered_json j;
    j["model"] = model->name();
    j["ball"] = ball.name;
    j["drop_height_m"] = o.drop_m;
    j["members"] = o.ensemble.members;
    j["height_jitter_m"] = o.ensemble.height_jitter_m;
    j["turn_jitter_rad"] = o.ensemble.turn_jitter_rad;
    j["bounce_heights_m"] = e.mean_m;
    j["bounce_heights_sd_m"] = sd;  // both below, in quadrature
    j["bounce_heights_chaos_sd_m"] = e.sd_m;
    j["bounce_heights_parameter_sd_m"] = param_sd;
    j["single_run_heights_m"] = e.single_m;
    if (run.known) {  // the run's start apex, and the bounces as its peaks.csv numbers them
      j["start"] = {{"drop", run.drop}, {"bounce", run.bounce}, {"t_s", run.t_s}};
      j["bounces"] = numbers;
      j["single_run_apex_t_s"] = apex_t_s;
    }
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("%s, %s dropped from %.6g m: %d runs (release +- %.3g mm, turned +- %.3g deg)\n",
              model->name().c_str(), ball.name.c_str(), o.drop_m, o.ensemble.members,
              o.ensemble.height_jitter_m * 1000, o.ensemble.turn_jitter_rad * 180 / M_PI);
  if (param_runs > 0)
    std::printf("spread: the runs' and the fitted coefficients' uncertainty (their covariance, %d runs), in quadrature\n",
                param_runs);
  if (run.known)
    std::printf("from the run's start apex: drop %d, bounce #%d at %.4f s (peaks.csv); bounces numbered and timed as "
                "there%s\n",
                run.drop, run.bounce, run.t_s, run.time_scale == 1 ? "" : " (the file's slowed clock)");
  fmt::print("{:>6} {:>12} {:>10} {:>10} {:>10} {:>14}{}\n", "bounce", "mean_m", "sd_mm", "chaos_mm", "coeffs_mm",
             "single_run_m", run.known ? "   apex_t_s  recorded_m" : "");
  for (size_t i = 0; i < e.mean_m.size(); ++i) {
    // single_run_m as "{:f}"; recorded_m cut (not rounded) to six characters.
    fmt::print("{:6} {:>12.4f} {:>10.2f} {:>10.2f} {:>10.2f} {:>14}", run.known ? numbers[i] : static_cast<int>(i + 1),
               e.mean_m[i], sd[i] * 1000, e.sd_m[i] * 1000, param_sd[i] * 1000,
               i < e.single_m.size() ? fmt::format("{:f}", e.single_m[i]) : "-");
    if (run.known) {
      const auto rec = run.recorded_m.find(numbers[i]);
      fmt::print(" {:>10.4f}  {:>10}", apex_t_s[i],
                 rec == run.recorded_m.end() ? "-" : fmt::format("{:f}", rec->second).substr(0, 6));
    }
    fmt::print("\n");
  }
}

}  // namespace

void AddPredictCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "predict",
      "Expected bounce heights (ball bottom above the floor, m) of a fitted ball dropped from "
      "--drop: the mean and spread of an ensemble of tiny perturbations of the release, and the "
      "single unperturbed run (what `simulate` prints); either model.");
  cmd->footer("Examples:\n  bouncefit predict --coeffs out/sample/coefficients.json --drop 1.6 --gltf ball.glb\n"
              "  bouncefit predict --coeffs out/sample/coefficients.json    # the run's own drop, on its timeline");
  auto o = std::make_shared<PredictOptions>();
  cmd->add_option("--coeffs", o->coeffs, "a fit's coefficients.json (or a coefficient table)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--drop,--drop-height", o->drop_m,
                  "ball bottom above the floor at release, metres (a run's coefficients.json without it: "
                  "the apex its fit started from, the bounces numbered and timed as its peaks.csv)");
  AddBallFlags(cmd, &o->ball);
  cmd->add_flag("--json", o->json,
                "one JSON object: bounce_heights_m (means), bounce_heights_sd_m (the runs' spread and "
                "the fitted coefficients' uncertainty in quadrature; each also on its own: "
                "bounce_heights_chaos_sd_m, bounce_heights_parameter_sd_m), single_run_heights_m; "
                "from a run's start apex also start, bounces (peaks.csv's numbers) and single_run_apex_t_s");
  cmd->add_option("--gltf", o->gltf,
                  "also write the single run as a glTF 2.0 binary (.glb: metres, y up, the floor "
                  "at y = 0, real seconds since the release) for Blender and other tools");
  cmd->add_option("--members", o->ensemble.members, "runs in the ensemble")->capture_default_str();
  cmd->add_option("--height-jitter", o->ensemble.height_jitter_m,
                  "release heights uniform in +- this, metres")
      ->capture_default_str();
  cmd->add_option("--turn-jitter", o->ensemble.turn_jitter_rad,
                  "turns about the vertical uniform in +- this, radians")
      ->capture_default_str();
  cmd->add_option("--min-height", o->min_height_m, "bounces lower than this are not reported, m")
      ->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "simulated time at most, s (0: from the drop)");
  cmd->add_option("--threads", o->ensemble.threads, "parallel runs (0: all cores)")
      ->capture_default_str();
  cmd->callback([o] { Run(*o); });
}

}  // namespace bouncefit::cli
