#pragma once
// One cell of the CSV files a run writes: a number with a fixed count of decimals, or empty
// when it is unknown (docs/FORMATS.md).
#include <fmt/format.h>

#include <cmath>
#include <string>

namespace bouncefit {

inline std::string CsvCell(double v, int decimals) {
  return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : std::string();
}

}  // namespace bouncefit
