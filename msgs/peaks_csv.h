#pragma once
// peaks.csv (docs/FORMATS.md): one row per bounce of a run, written by the detect node and
// read back by everything else (`report`, `fit --peaks`, the tests). Empty cells are unknown.
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "bouncefit/bounce_peak_t.hpp"

namespace bouncefit {

struct PeaksCsvRow {
  static constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
  int bounce = 0;
  double t_s = 0;                      // apex time, s since the stream's first frame
  double height_m = kUnknown;          // as the picture measured it when it was emitted
  double height_px = kUnknown;
  double flight_height_m = kUnknown;   // g dt^2 / 8 from the impacts around it
  double emitted_t_s = kUnknown;       // when it was emitted (empty: heard only)
  std::string heard;                   // "both", "heard only" or ""
  double fused_height_m = kUnknown;    // the height to quote (and the one the fit takes)
  double refit_height_m = kUnknown;    // refitted with every arc of its drop
  int drop = 0;                        // the drop of the stream it belongs to, from 0 (its own scale)
  // The height to quote: fused, else the live one (a file without the column).
  double HeightToUse() const { return std::isfinite(fused_height_m) ? fused_height_m : height_m; }
};

// A final row (revision 3) of BOUNCE_PEAK as a peaks.csv row; t0: the stream's first frame.
PeaksCsvRow PeaksCsvRowOf(const bounce_peak_t& m, int64_t t0_utime);

// One row as a line of peaks.csv, its newline included (unknown cells empty).
std::string PeaksCsvLine(const PeaksCsvRow& row);

// Writes the rows through a temporary file renamed over `path` (a reader never sees half).
// Throws std::runtime_error naming the file when it cannot be written.
void WritePeaksCsv(const std::filesystem::path& path, const std::vector<PeaksCsvRow>& rows);

// Reads a peaks.csv (its columns by header name; bounce and height_m required, any other
// may be absent: t_s 0). Throws std::runtime_error with "<file> line <n>: <why>".
std::vector<PeaksCsvRow> ReadPeaksCsv(const std::filesystem::path& path);

}  // namespace bouncefit
