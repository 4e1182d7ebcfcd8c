#include "fit/fit_models.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "fit/point_mass_model.h"
#include "fit/soft_ball_model.h"

namespace bouncefit {

std::string FitModelNames() { return "bullet-softbody, point-mass"; }

std::unique_ptr<BallModel> MakeFitModel(const std::string& name, const BallPreset& ball) {
  if (name == "bullet-softbody" || name == "soft") return std::make_unique<SoftBallModel>(ball);
  if (name == "point-mass") return std::make_unique<PointMassModel>(ball);
  throw std::invalid_argument("unknown model '" + name + "' (known: " + FitModelNames() + ")");
}

CoefficientTable ParseCoefficientTable(std::string_view text, const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw std::runtime_error(source + ": not JSON (" + e.what() + ")");
  }
  CoefficientTable t;
  t.source = source;
  if (!j.is_object()) return t;
  if (j.contains("time_step_s") && j["time_step_s"].is_number())
    t.time_step_s = j["time_step_s"].get<double>();
  if (j.contains("position_iterations") && j["position_iterations"].is_number())
    t.position_iterations = j["position_iterations"].get<int>();
  // {"coefficients": {"name": value | {"value": v}, ...}, ...} or a flat {"name": value}.
  const nlohmann::json& table = j.contains("coefficients") ? j["coefficients"] : j;
  if (!table.is_object()) return t;
  for (auto it = table.begin(); it != table.end(); ++it) {
    if (it.value().is_number()) t.values[it.key()] = it.value().get<double>();
    else if (it.value().is_object() && it.value().contains("value") && it.value()["value"].is_number())
      t.values[it.key()] = it.value()["value"].get<double>();
  }
  return t;
}

CoefficientTable LoadCoefficientTable(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return ParseCoefficientTable(text, path.string());
}

std::optional<CoefficientTable> SoftBallPresetTable(const std::string& ball) {
  const std::string file = "soft_ball_" + ball + ".json";
  if (const char* dir = std::getenv("BOUNCEFIT_PRESETS_DIR")) {
    const auto p = std::filesystem::path(dir) / file;
    if (std::filesystem::exists(p)) return LoadCoefficientTable(p);
  }
  if (const auto text = EmbeddedPresetText(file))
    return ParseCoefficientTable(*text, "embedded fit/presets/" + file);
  return std::nullopt;
}

void ConfigureSessionForModel(const BallModel& model, const BallPreset& ball,
                              FitSessionConfig* config) {
  const auto* soft = dynamic_cast<const SoftBallModel*>(&model);
  if (!soft) return;
  config->time_step_s = soft->config().time_step_s;
  config->iterations = soft->config().position_iterations;
  // Measured with bench/fit_bench.cc's screening: what moves the heights most, in order.
  if (config->live_priority.empty())
    config->live_priority = {"rebound_boost", "linear_stiffness", "contact_hardness", "drag",
                             "volume_conservation", "pressure"};
  // Warm start: the model's coefficient table for this ball, when there is one (values the
  // model does not know are ignored by the session).
  if (const auto table = SoftBallPresetTable(ball.name))
    for (const auto& [name, v] : table->values)
      if (!config->start.count(name)) config->start[name] = v;
}

}  // namespace bouncefit
