#include "fit/fit_session_config.h"

#include <algorithm>
#include <stdexcept>

#include "fit/fit_objective.h"

namespace bouncefit {

namespace {

bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

void RequireOneOf(const std::string& what, const std::string& value, const std::string& a, const std::string& b) {
  if (value != a && value != b)
    throw std::invalid_argument("unknown " + what + " '" + value + "' (known: " + a + ", " + b + ")");
}

}  // namespace

void ValidateFitSessionConfig(const FitSessionConfig& config, const BallModel& model) {
  RequireOneOf("live method", config.live_method, "gauss-newton", "search");
  RequireOneOf("objective", config.objective, "segments", "drop");
  RequireOneOf("impact", config.impact, "boost", "restitution");
  RequireOneOf("fit method", config.method, "nlopt", "paper");
  const auto specs = model.Coefficients();
  for (const auto& name : config.free) {
    bool found = false;
    for (const auto& s : specs) found = found || s.name == name;
    if (!found)
      throw std::invalid_argument("model '" + model.name() + "' has no coefficient '" + name + "'");
  }
}

std::vector<CoefficientSpec> FreeCoefficients(const BallModel& model, const FitSessionConfig& config) {
  std::vector<CoefficientSpec> free;
  for (const auto& s : model.Coefficients()) {
    if (!config.free.empty()) {
      if (Contains(config.free, s.name)) free.push_back(s);
      continue;
    }
    if (!(s.upper > s.lower)) continue;
    bool never = s.name == "radius";
    for (const auto& pattern : config.never_fit)
      never = never || s.name.find(pattern) != std::string::npos;
    if (!never) free.push_back(s);
  }
  std::stable_sort(free.begin(), free.end(), [](const auto& a, const auto& b) {
    return PaperPriority(a.name) < PaperPriority(b.name);
  });
  return free;
}

std::vector<std::string> LiveOrder(const std::vector<CoefficientSpec>& free, const FitSessionConfig& config) {
  std::vector<std::string> order;
  for (const auto& name : config.live_priority)
    for (const auto& s : free)
      if (s.name == name && !Contains(order, name)) order.push_back(name);
  for (const auto& s : free)
    if (!Contains(order, s.name)) order.push_back(s.name);
  return order;
}

std::vector<CoefficientSpec> FirstCoefficients(const std::vector<CoefficientSpec>& free,
                                               const std::vector<std::string>& order, int n) {
  std::vector<CoefficientSpec> out;
  for (const auto& name : order) {
    if (static_cast<int>(out.size()) >= n) break;
    for (const auto& s : free)
      if (s.name == name) out.push_back(s);
  }
  return out;
}

bool UsesRestitutionLaw(const FitSessionConfig& config, const BallModel& model, const BallModel* quick_model) {
  if (config.impact != "restitution" || !quick_model) return false;
  for (const auto& s : model.Coefficients())
    if (s.name == "rebound_restitution") return true;
  return false;
}

}  // namespace bouncefit
