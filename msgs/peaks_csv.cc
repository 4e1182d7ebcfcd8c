#include "msgs/peaks_csv.h"
#include "msgs/csv_cell.h"

#include <fmt/format.h>

#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "msgs/msg_json.h"

namespace bouncefit {
namespace {

constexpr const char* kHeader =
    "bounce,t_s,height_m,height_px,flight_height_m,emitted_t_s,heard,fused_height_m,refit_height_m,drop";

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::stringstream ss(line);
  while (std::getline(ss, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

}  // namespace

PeaksCsvRow PeaksCsvRowOf(const bounce_peak_t& m, int64_t t0) {
  PeaksCsvRow r;
  r.bounce = m.bounce;
  r.t_s = SecondsSince(m.apex_utime, t0);
  r.height_m = m.height_m;
  r.height_px = m.height_px;
  r.flight_height_m = m.flight_height_m;
  r.emitted_t_s = m.emitted_utime ? SecondsSince(m.emitted_utime, t0) : PeaksCsvRow::kUnknown;
  r.heard = m.heard;
  r.fused_height_m = m.fused_height_m;
  r.refit_height_m = m.refit_height_m;
  r.drop = m.sequence;
  return r;
}

std::string PeaksCsvLine(const PeaksCsvRow& r) {
  return fmt::format("{},{},{},{},{},{},{},{},{},{}\n", r.bounce, CsvCell(r.t_s, 6), CsvCell(r.height_m, 5),
                     CsvCell(r.height_px, 3), CsvCell(r.flight_height_m, 5), CsvCell(r.emitted_t_s, 6), r.heard,
                     CsvCell(r.fused_height_m, 5), CsvCell(r.refit_height_m, 5), r.drop);
}

void WritePeaksCsv(const std::filesystem::path& path, const std::vector<PeaksCsvRow>& rows) {
  const std::string tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    if (!f) throw std::runtime_error("cannot write '" + tmp + "'");
    f << kHeader << '\n';
    for (const PeaksCsvRow& r : rows) f << PeaksCsvLine(r);
    if (!f) throw std::runtime_error("cannot write '" + tmp + "'");
  }
  std::filesystem::rename(tmp, path);
}

std::vector<PeaksCsvRow> ReadPeaksCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path.string() + ": empty");
  std::map<std::string, size_t> column;
  const auto header = Split(line);
  for (size_t i = 0; i < header.size(); ++i) column[header[i]] = i;
  for (const char* need : {"bounce", "height_m"})
    if (!column.count(need))
      throw std::runtime_error(path.string() + ": no column '" + need + "' (not a peaks.csv?)");
  std::vector<PeaksCsvRow> rows;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const auto cells = Split(line);
    const auto where = path.string() + " line " + std::to_string(n) + ": ";
    auto text = [&](const char* name) -> std::string {
      const auto it = column.find(name);
      return it != column.end() && it->second < cells.size() ? cells[it->second] : std::string();
    };
    auto number = [&](const char* name) {
      const std::string t = text(name);
      if (t.empty()) return PeaksCsvRow::kUnknown;
      size_t used = 0;
      double v = 0;
      try {
        v = std::stod(t, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != t.size()) throw std::runtime_error(where + "'" + t + "' in " + name + " is not a number");
      return v;
    };
    PeaksCsvRow r;
    const double bounce = number("bounce");
    if (!std::isfinite(bounce) || bounce != std::floor(bounce) || bounce < 0)
      throw std::runtime_error(where + "bounce must be a whole number >= 0");
    r.bounce = static_cast<int>(bounce);
    r.t_s = number("t_s");
    if (!std::isfinite(r.t_s)) r.t_s = 0;  // a hand-made file of heights only
    r.height_m = number("height_m");
    r.height_px = number("height_px");
    r.flight_height_m = number("flight_height_m");
    r.emitted_t_s = number("emitted_t_s");
    r.heard = text("heard");
    r.fused_height_m = number("fused_height_m");
    r.refit_height_m = number("refit_height_m");
    const double drop = number("drop");
    r.drop = std::isfinite(drop) && drop >= 0 ? static_cast<int>(drop) : 0;
    rows.push_back(r);
  }
  return rows;
}

}  // namespace bouncefit
