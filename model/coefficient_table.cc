#include "model/coefficient_table.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace bouncefit {

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
  for (const char* key : {"position_iterations", "iterations"})
    if (!t.position_iterations && j.contains(key) && j[key].is_number())
      t.position_iterations = j[key].get<int>();
  if (j.contains("model") && j["model"].is_string()) t.model = j["model"].get<std::string>();
  if (j.contains("drop_height_m") && j["drop_height_m"].is_number())
    t.drop_height_m = j["drop_height_m"].get<double>();
  if (j.contains("ball") && j["ball"].is_string()) t.ball = j["ball"].get<std::string>();
  if (j.contains("ball") && j["ball"].is_object()) {
    const auto& b = j["ball"];
    if (b.contains("name") && b["name"].is_string()) t.ball = b["name"].get<std::string>();
    if (b.contains("mass_kg") && b["mass_kg"].is_number()) t.mass_kg = b["mass_kg"].get<double>();
    if (b.contains("diameter_m") && b["diameter_m"].is_number())
      t.diameter_m = b["diameter_m"].get<double>();
  }
  // A fit's "values" (every value its model ran with), else {"coefficients": {"name": value |
  // {"value": v}, ...}, ...}, else a flat {"name": value}. A fit's "coefficients" lists only
  // what it may fit: read alone, the coefficients it held fixed would fall to their defaults.
  const nlohmann::json& table = j.contains("values") && j["values"].is_object() ? j["values"]
                                : j.contains("coefficients")                    ? j["coefficients"]
                                                                                : j;
  if (!table.is_object()) return t;
  const bool flat = &table == &j;
  for (auto it = table.begin(); it != table.end(); ++it) {
    if (flat && (it.key() == "time_step_s" || it.key() == "position_iterations" ||
                 it.key() == "iterations" || it.key() == "drop_height_m"))
      continue;  // what the table holds for, not a coefficient
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
    return ParseCoefficientTable(*text, "embedded model/presets/" + file);
  return std::nullopt;
}

}  // namespace bouncefit
