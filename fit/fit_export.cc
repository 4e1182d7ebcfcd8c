#include "fit/fit_export.h"

#include "fit/fitted_ball_project.h"
#include "model/model_by_name.h"
#include "model/soft_ball_model.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace bouncefit {

namespace {

// JSON has no NaN: an unknown value is null.
nlohmann::json JsonNumberOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

}  // namespace

nlohmann::json RestitutionJson(const FitUpdate& u) {
  const RestitutionConsistency& r = u.restitution;
  nlohmann::json points = nlohmann::json::array();
  for (const auto& p : u.restitution_points)
    points.push_back({{"drop", p.drop}, {"bounce", p.bounce}, {"impact_speed_mps", p.speed_mps}, {"e", p.e},
                      {"sigma", p.sigma}});
  std::vector<nlohmann::json> drop_e, drop_sigma;
  for (size_t d = 0; d < r.drop_e.size(); ++d) {
    drop_e.push_back(JsonNumberOrNull(r.drop_e[d]));
    drop_sigma.push_back(JsonNumberOrNull(r.drop_e_sigma[d]));
  }
  return {{"points", points},          {"reference_speed_mps", JsonNumberOrNull(r.reference_mps)},
          {"scatter", JsonNumberOrNull(r.scatter)}, {"drop_e", drop_e},
          {"drop_e_sigma", drop_sigma}, {"drops_agree", r.drops_agree},
          {"chi2_drops", JsonNumberOrNull(r.chi2_drops)}, {"suspect", r.suspect}};
}

nlohmann::json FitUpdateToJson(const FitUpdate& u, const BallPreset& ball) {
  nlohmann::json coeffs = nlohmann::json::object();
  for (const auto& c : u.coefficients)
    coeffs[c.name] = {{"value", JsonNumberOrNull(c.value)},   {"sigma", JsonNumberOrNull(c.sigma)},
                      {"identifiable", c.identifiable}, {"unit", c.unit},
                      {"note", c.note}, {"at_bound", c.bound.empty() ? nlohmann::json() : nlohmann::json(c.bound)}};
  nlohmann::json values = nlohmann::json::object();
  for (const auto& [name, v] : u.values) values[name] = JsonNumberOrNull(v);
  return {{"model", u.model},
          {"method", u.method},
          {"final", u.final},
          {"sequence", u.sequence},
          {"after_bounce", u.after_bounce},
          // The apex the simulation starts from: 0 the release, else the first apex in view.
          {"start_bounce", u.start_bounce},
          {"ball", {{"name", ball.name}, {"mass_kg", ball.mass_kg}, {"diameter_m", ball.diameter_m}}},
          {"time_step_s", u.time_step_s},
          {"iterations", u.iterations},
          {"drop_height_m", u.drop_height_m},
          {"coefficients", coeffs},
          {"values", values},
          {"no_effect", u.no_effect},
          {"unidentified", u.unidentified},
          {"covariance", {{"names", u.covariance_names}, {"matrix", u.covariance}}},
          {"recorded_m", u.recorded_m},
          {"simulated_m", u.simulated_m},
          {"residual_m", JsonNumberOrNull(u.residual_m)},
          {"segment_simulated_m", u.segment_simulated_m},
          {"segment_residual_m", JsonNumberOrNull(u.segment_residual_m)},
          {"free_run_mean_m", u.free_run_mean_m},
          {"free_run_sd_m", u.free_run_sd_m},
          {"free_run_residual_m", JsonNumberOrNull(u.free_run_residual_m)},
          // A joint fit: the other drops' heights follow this drop's in the lists above.
          {"other_drop_heights_m", u.other_drop_heights_m},
          {"other_drop_bounces", u.other_drop_bounces},
          {"warning", u.warning},
          {"held", u.held},
          // Final fit: the bounces' restitution impact by impact, and whether they agree.
          {"restitution", u.final ? RestitutionJson(u) : nlohmann::json()},
          {"evaluations", u.evaluations},
          {"wall_time_s", u.wall_time_s}};
}

nlohmann::json FitGltfExtras(const FitUpdate& u, const BallPreset& ball,
                             const FitExportContext& context) {
  auto value = [&](const char* name) {
    const auto it = u.values.find(name);
    return it == u.values.end() ? nlohmann::json() : JsonNumberOrNull(it->second);
  };
  nlohmann::json j;
  j["ball"] = {{"preset", ball.name}, {"diameter_m", ball.diameter_m}, {"mass_kg", ball.mass_kg}};
  // The soft ball's law and the point mass's name their coefficients differently.
  const bool soft = u.values.count("rebound_restitution") > 0;
  j["restitution_law"] = {
      {"formula", "e(v) = e0 - k v, v the impact speed in m/s"},
      {"e0", soft ? value("rebound_restitution") : value("restitution")},
      {"k_per_mps", soft ? value("rebound_restitution_per_mps") : value("restitution_per_mps")}};
  j["drag_coefficient"] = soft ? value("drag") : value("drag_coefficient");
  nlohmann::json values = nlohmann::json::object();
  for (const auto& [name, v] : u.values) values[name] = JsonNumberOrNull(v);
  j["fit"] = {{"model", u.model},
              {"method", u.method},
              {"drop_height_m", u.drop_height_m},
              {"bounces", u.recorded_m.size()},
              {"recorded_m", u.recorded_m},
              {"simulated_m", u.simulated_m},
              {"residual_m", JsonNumberOrNull(u.residual_m)},
              {"time_step_s", u.time_step_s},
              {"iterations", u.iterations},
              {"values", values},
              {"warning", u.warning}};
  if (!context.clip.empty()) j["fit"]["clip"] = context.clip;
  if (!context.fitted_by.empty()) j["fit"]["fitted_by"] = context.fitted_by;
  if (context.drops && !context.drops->empty()) {  // where the animation's t = 0 is in the clip
    const FitDrop& d = context.drops->front();
    j["start"] = {{"bounce", d.start_bounce}, {"drop", d.drop}, {"t_s", JsonNumberOrNull(d.start_t_s)},
                  {"height_m", JsonNumberOrNull(d.start_height_m)}, {"time_scale", 1 / context.run_s_per_real_s}};
  }
  return j;
}

FittedBallGltf WriteFitGltf(const std::filesystem::path& path, const FitUpdate& u,
                            const BallPreset& ball, double drop_height_m,
                            const FitExportContext& context) {
  std::unique_ptr<BallModel> model;
  if (u.model == "bullet-softbody") {  // the step and iterations the coefficients hold for
    SoftBallModelConfig config;
    if (u.time_step_s > 0) config.time_step_s = u.time_step_s;
    if (u.iterations > 0) config.position_iterations = u.iterations;
    model = std::make_unique<SoftBallModel>(ball, config);
  } else {
    model = MakeBallModel(u.model, ball);
  }
  // The animation ends where the fit's safety drops end: hops of a tenth of the ball's
  // diameter (at least 1 cm) are contact chatter, not bounces.
  FittedBallGltfOptions options;
  options.min_bounce_height_m = ball.chatter_hop_m();
  return WriteFittedBallGltf(path, *model, ball, u.values, drop_height_m,
                             FitGltfExtras(u, ball, context), context.recorded, options);
}

std::vector<std::filesystem::path> WriteFitExports(const std::filesystem::path& dir,
                                                   const FitUpdate& u, const BallPreset& ball,
                                                   const FitExportContext& context) {
  std::filesystem::create_directories(dir);
  const auto json_path = dir / "coefficients.json";
  {
    nlohmann::json j = FitUpdateToJson(u, ball);
    if (context.drops && !context.drops->empty()) {
      // The fit's own drop by peaks.csv's numbers (the fit counts bounces as first emitted).
      const FitDrop& own = context.drops->front();
      j["drop"] = own.drop;
      j["start_bounce"] = own.start_bounce;
      j["start_t_s"] = JsonNumberOrNull(own.start_t_s);
      if (!own.bounces.empty()) j["after_bounce"] = own.bounces.back();
      j["drops"] = FitDropsToJson(*context.drops);
      // Real seconds per second of the run's clock (summary.json's clock.time_scale).
      j["time_scale"] = 1 / context.run_s_per_real_s;
    }
    std::ofstream out(json_path);
    out << j.dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + json_path.string());
  }
  std::vector<std::filesystem::path> written{json_path};
  if (u.drop_height_m > 0)  // a fit that knows no drop height has no drop to animate
    written.push_back(WriteFitGltf(dir / "fitted_ball.glb", u, ball, u.drop_height_m, context).path);
  if (FittedBallProjectUnavailable(u.model).empty()) {
    written.push_back(WriteFittedBallProject(dir, u, ball));
  } else {  // said where a user looks for it
    const auto note = dir / "fitted_ball" / "README.md";
    std::filesystem::create_directories(note.parent_path());
    std::ofstream out(note);
    out << "# fitted_ball: nothing to build\n\n" << FittedBallProjectUnavailable(u.model) << ".\n";
    if (!out) throw std::runtime_error("cannot write " + note.string());
    written.push_back(note);
  }
  return written;
}

}  // namespace bouncefit
