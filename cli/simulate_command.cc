// bouncefit simulate: run the Bullet soft-body ball (model/soft_ball_model.h) for given
// coefficients and print its bounce heights and trajectory; optionally render it as a clip
// with synth's renderer.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/ball_flags.h"
#include "cli/commands.h"
#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/soft_ball_model.h"
#include "synth/synth_clip.h"

namespace bouncefit::cli {
namespace {

struct SimulateOptions {
  std::string coeffs;
  BallFlags ball;  // not given: the coefficient file's ball, else pingpong
  double drop_m = 1.0;
  double duration_s = 6.0;
  double min_height_m = 0.01;
  double rate_hz = 120;
  bool csv = false, json = false, list = false, no_trajectory = false;
  std::string render;
};

// --coeffs: "preset" (the ball's stored table, fit/fit_models.h), a JSON file, or k=v,k=v.
CoefficientValues ReadCoefficients(const std::string& text, const std::string& ball,
                                   const SoftBallModel& model) {
  if (text.empty()) return {};
  std::optional<CoefficientTable> table;
  if (text == "preset") {
    table = SoftBallPresetTable(ball);
    if (!table) throw std::runtime_error("no stored coefficients for ball '" + ball + "'");
  } else if (text.find('=') == std::string::npos) {
    table = LoadCoefficientTable(text);
  }
  if (!table) return ParseCoefficientList(text);
  // The table's time step and iterations, when it names them, must be the model's: the
  // coefficients hold for those only.
  if (table->time_step_s && std::abs(*table->time_step_s - model.config().time_step_s) > 1e-12)
    throw std::runtime_error(fmt::format("{}: coefficients for time step {:.6g} s, the model steps {:.6g} s",
                                         table->source, *table->time_step_s, model.config().time_step_s));
  if (table->position_iterations &&
      *table->position_iterations != model.config().position_iterations)
    throw std::runtime_error(table->source + ": coefficients for " +
                             std::to_string(*table->position_iterations) +
                             " position iterations, the model uses " +
                             std::to_string(model.config().position_iterations));
  if (table->values.empty()) throw std::runtime_error(table->source + ": no coefficients in it");
  return table->values;
}

void ListCoefficients(const SoftBallModel& model) {
  fmt::print("{:<28} {:<14} {:>10} {:>10} {:>10}  {}\n", "name", "unit", "default", "lower", "upper", "what it is");
  for (const auto& s : model.Coefficients())
    fmt::print("{:<28} {:<14} {:>10.6g} {:>10.6g} {:>10.6g}  {}{}\n", s.name, s.unit.empty() ? "-" : s.unit,
               s.default_value, s.lower, s.upper, s.discrete ? "(integer) " : "", s.description);
  fmt::print("fixed for this model: time step {:.6g} s, {} position iterations, gravity {:.6g} m/s^2\n",
             model.config().time_step_s, model.config().position_iterations, model.config().gravity_mps2);
}

void Run(const SimulateOptions& o) {
  if (o.csv && o.json) throw std::invalid_argument("--csv and --json exclude each other");
  if (!(o.rate_hz > 0)) throw std::invalid_argument("--rate must be > 0 Hz");
  // A fit's file names its ball (and its size and mass): the heights are that ball's.
  std::optional<CoefficientTable> file;
  if (!o.coeffs.empty() && o.coeffs != "preset" && o.coeffs.find('=') == std::string::npos)
    file = LoadCoefficientTable(o.coeffs);
  BallFlags named;
  if (file) named = {file->ball, file->diameter_m.value_or(0), file->mass_kg.value_or(0)};
  if (!o.ball.name.empty() && !named.name.empty() && o.ball.name != named.name)
    throw std::invalid_argument(o.coeffs + " holds coefficients for the " + named.name + " ball, not " +
                                o.ball.name);
  const BallPreset ball = ResolveBall(o.ball, named);
  const SoftBallModel model(ball);
  if (o.list) {
    ListCoefficients(model);
    return;
  }
  const CoefficientValues given = ReadCoefficients(o.coeffs, ball.name, model);
  std::string error;
  const CoefficientValues values = model.Complete(given, &error);
  if (!error.empty()) throw std::invalid_argument(error);

  SimulationOptions so;
  so.drop_height_m = o.drop_m;
  so.duration_s = o.duration_s;
  so.min_bounce_height_m = o.min_height_m;
  so.record_trajectory = !o.no_trajectory || !o.render.empty();
  so.trajectory_rate_hz = o.rate_hz;
  if (!o.render.empty()) {
    // The renderer interpolates between samples: give it every step, and the whole
    // duration (no early stop).
    so.trajectory_rate_hz = 1 / model.config().time_step_s;
    so.min_bounce_height_m = -1;
  }
  SimulationResult r = model.Simulate(values, so);
  if (!r.ok) throw std::runtime_error("simulation failed: " + r.failure);
  if (!o.render.empty()) {  // ran without early stop for the clip: report as asked
    size_t n = 0;
    while (n < r.bounce_heights_m.size() && r.bounce_heights_m[n] >= o.min_height_m) ++n;
    r.bounce_heights_m.resize(n);
    r.apex_times_s.resize(n);
  }

  std::vector<TrajectorySample> printed;  // at --rate
  if (!o.no_trajectory) {
    const double step = 1 / o.rate_hz;
    double next = 0;
    for (const auto& s : r.trajectory)
      if (s.t_s >= next - 1e-9) {
        printed.push_back(s);
        next += step;
      }
  }

  if (o.json) {
    nlohmann::ordered_json j;
    j["model"] = model.name();
    j["ball"] = ball.name;
    j["diameter_m"] = ball.diameter_m;
    j["mass_kg"] = ball.mass_kg;
    j["drop_height_m"] = o.drop_m;
    j["time_step_s"] = model.config().time_step_s;
    j["position_iterations"] = model.config().position_iterations;
    nlohmann::ordered_json c;
    for (const auto& s : model.Coefficients()) c[s.name] = values.at(s.name);
    j["coefficients"] = c;
    j["bounce_heights_m"] = r.bounce_heights_m;
    j["apex_times_s"] = r.apex_times_s;
    j["impact_times_s"] = r.impact_times_s;
    j["wall_time_s"] = r.wall_time_s;
    nlohmann::ordered_json traj = nlohmann::ordered_json::array();
    for (const auto& s : printed)
      traj.push_back({{"t_s", s.t_s},
                      {"bottom_height_m", s.bottom_height_m},
                      {"center_height_m", s.center_height_m},
                      {"width_height_ratio", s.width_height_ratio}});
    j["trajectory"] = traj;
    std::printf("%s\n", j.dump(2).c_str());
  } else if (o.csv) {
    std::printf("bounce,apex_t_s,height_m\n");
    for (size_t i = 0; i < r.bounce_heights_m.size(); ++i)
      std::printf("%zu,%.6f,%.6f\n", i + 1, r.apex_times_s[i], r.bounce_heights_m[i]);
    if (!o.no_trajectory) {
      std::printf("\nt_s,bottom_height_m,center_height_m,width_height_ratio\n");
      for (const auto& s : printed)
        std::printf("%.6f,%.6f,%.6f,%.5f\n", s.t_s, s.bottom_height_m, s.center_height_m,
                    s.width_height_ratio);
    }
  } else {
    fmt::print("{}, {} ({:.6g} m, {:.6g} kg) dropped from {:.6g} m; time step {:.6g} s, {} iterations; {:.6g} s in "
               "{:.3f} s\n",
               model.name(), ball.name, ball.diameter_m, ball.mass_kg, o.drop_m, model.config().time_step_s,
               model.config().position_iterations, o.duration_s, r.wall_time_s);
    std::printf("bounce heights (m):");
    for (double h : r.bounce_heights_m) std::printf(" %.4f", h);
    std::printf("%s\n", r.bounce_heights_m.empty() ? " none" : "");
    std::printf("apex times (s):    ");
    for (double t : r.apex_times_s) std::printf(" %.4f", t);
    std::printf("\n");
    if (!o.no_trajectory) {
      std::printf("%10s %12s %12s %12s\n", "t_s", "bottom_m", "centre_m", "width/height");
      for (const auto& s : printed)
        std::printf("%10.4f %12.5f %12.5f %12.4f\n", s.t_s, s.bottom_height_m,
                    s.center_height_m, s.width_height_ratio);
    }
  }

  if (!o.render.empty()) {
    SynthClipConfig clip;
    clip.ball = ball;
    clip.drop_height_m = o.drop_m;
    clip.duration_s = clip.hold_s + o.duration_s;
    clip.out = o.render;
    const SynthTrajectory t = SynthTrajectoryFromSimulation(r, o.drop_m, model.name());
    const SynthClipResult c = RenderSynthTrajectoryClip(clip, t);
    std::fprintf(o.json || o.csv ? stderr : stdout, "simulate: rendered %s (%d frames at %g fps)\n",
                 c.clip_path.string().c_str(), c.truth.frame_count, c.truth.fps);
  }
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "simulate",
      "Simulate the Bullet soft-body ball (docs/MODEL.md) for given coefficients: prints its "
      "bounce heights (ball bottom above the floor, m, measured from 120 Hz samples like the "
      "detector) and its trajectory; --render draws it as a clip.");
  auto o = std::make_shared<SimulateOptions>();
  cmd->add_option("--coeffs", o->coeffs,
                  "Coefficients: a JSON file ({\"coefficients\": {name: value}}), name=value,... "
                  "or 'preset' (the ball's stored table); missing ones take their defaults");
  AddBallFlags(cmd, &o->ball);
  cmd->add_option("--drop,--drop-height", o->drop_m,
                  "Ball bottom above the floor at release, metres")
      ->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Simulated time at most, seconds")
      ->capture_default_str();
  cmd->add_option("--min-height", o->min_height_m,
                  "Stop once bounces fall below this height, metres")
      ->capture_default_str();
  cmd->add_option("--rate", o->rate_hz, "Trajectory sampling rate, Hz")->capture_default_str();
  cmd->add_flag("--no-trajectory", o->no_trajectory, "Print the bounce heights only");
  cmd->add_flag("--csv", o->csv, "CSV: a bounce table, a blank line, a trajectory table");
  cmd->add_flag("--json", o->json, "One JSON object: model, coefficients, heights, trajectory");
  cmd->add_flag("--list-coeffs", o->list,
                "List the coefficients: name, unit, default, bounds, what each one is");
  cmd->add_option("--render", o->render,
                  "Also render the simulated drop as a clip (.avi or .mp4) with synth's renderer");
  cmd->footer(
      "Examples:\n"
      "  bouncefit simulate --ball pingpong --drop 1.0 --no-trajectory\n"
      "  bouncefit simulate --coeffs out/sample/coefficients.json --drop 1.6 --no-trajectory");
  cmd->callback([o] { Run(*o); });
}

}  // namespace bouncefit::cli
