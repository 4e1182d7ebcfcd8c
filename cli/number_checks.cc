#include "cli/number_checks.h"

#include <cmath>
#include <string>

namespace bouncefit {
namespace {

CLI::Validator AtLeast(bool strict) {
  const std::string what = strict ? "> 0" : ">= 0";
  return CLI::Validator(
      [strict, what](std::string& text) -> std::string {
        double v = 0;
        size_t used = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          return "must be a number " + what + ", not '" + text + "'";
        }
        if (used != text.size() || !std::isfinite(v) || (strict ? v <= 0 : v < 0))
          return "must be a number " + what + ", not " + text;
        return "";
      },
      "NUMBER " + what);
}

}  // namespace

CLI::Validator NonNegative() { return AtLeast(false); }
CLI::Validator Positive() { return AtLeast(true); }

}  // namespace bouncefit
