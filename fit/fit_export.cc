#include "fit/fit_export.h"

#include "fit/fitted_ball_project.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

namespace bouncefit {

namespace {

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

}  // namespace

nlohmann::json FitUpdateToJson(const FitUpdate& u, const BallPreset& ball) {
  nlohmann::json coeffs = nlohmann::json::object();
  for (const auto& c : u.coefficients)
    coeffs[c.name] = {{"value", Num(c.value)},   {"sigma", Num(c.sigma)},
                      {"identifiable", c.identifiable}, {"unit", c.unit},
                      {"note", c.note}};
  nlohmann::json values = nlohmann::json::object();
  for (const auto& [name, v] : u.values) values[name] = Num(v);
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
          {"residual_m", Num(u.residual_m)},
          {"segment_simulated_m", u.segment_simulated_m},
          {"segment_residual_m", Num(u.segment_residual_m)},
          {"free_run_mean_m", u.free_run_mean_m},
          {"free_run_sd_m", u.free_run_sd_m},
          {"free_run_residual_m", Num(u.free_run_residual_m)},
          // A joint fit: the other drops' heights follow this drop's in the lists above.
          {"other_drop_heights_m", u.other_drop_heights_m},
          {"other_drop_bounces", u.other_drop_bounces},
          {"warning", u.warning},
          {"held_at_preset", u.held_at_preset},
          {"evaluations", u.evaluations},
          {"wall_time_s", u.wall_time_s}};
}

std::vector<std::filesystem::path> WriteFitExports(const std::filesystem::path& dir,
                                                   const FitUpdate& u, const BallPreset& ball) {
  std::filesystem::create_directories(dir);
  const auto json_path = dir / "coefficients.json";
  {
    std::ofstream out(json_path);
    out << FitUpdateToJson(u, ball).dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + json_path.string());
  }
  std::vector<std::filesystem::path> written{json_path};
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
