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
    return ParseCoefficientTable(*text, "embedded model/presets/" + file);
  return std::nullopt;
}

}  // namespace bouncefit
