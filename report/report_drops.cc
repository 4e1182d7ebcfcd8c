#include "report/report_drops.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace bouncefit {
namespace {

namespace fs = std::filesystem;

struct DropRow {
  int drop = 0, bounce = 0;
  std::string clip_dir;
  double release_m = NAN, recorded_m = NAN, simulated_m = NAN;
};

double Cell(const std::string& s) { return s.empty() ? NAN : std::stod(s); }

// drops.csv: drop,clip_dir,release_m,bounce,recorded_m,simulated_m (docs/FORMATS.md).
std::vector<DropRow> ReadDropsCsv(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  std::string line;
  std::getline(in, line);
  if (line.rfind("drop,clip_dir,release_m,bounce,recorded_m,simulated_m", 0) != 0)
    throw std::runtime_error(file.string() + ": not a drops.csv (header '" + line + "')");
  std::vector<DropRow> rows;
  int n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    const std::vector<std::string> c = SplitCsvLine(line);
    try {
      if (c.size() != 6) throw std::invalid_argument("columns");
      rows.push_back({std::stoi(c[0]), std::stoi(c[3]), c[1], Cell(c[2]), Cell(c[4]), Cell(c[5])});
    } catch (const std::exception&) {
      throw std::runtime_error(file.string() + ":" + std::to_string(n) + ": malformed row '" + line + "'");
    }
  }
  if (rows.empty()) throw std::runtime_error(file.string() + ": no rows");
  return rows;
}

}  // namespace

bool IsSeveralClipsDirectory(const fs::path& dir) {
  return fs::exists(dir / "drops.csv") && !fs::exists(dir / "track.csv");
}

ReportOutcome WriteSeveralClipsReport(const fs::path& dir, const ReportOptions& options) {
  const auto rows = ReadDropsCsv(dir / "drops.csv");
  std::map<int, std::string> clip_of_drop;
  for (const auto& r : rows) {
    if (r.clip_dir.find('/') != std::string::npos || r.clip_dir == "..")
      throw std::runtime_error((dir / "drops.csv").string() + ": clip_dir '" + r.clip_dir + "' is not a sub-directory");
    clip_of_drop[r.drop] = r.clip_dir;
  }

  ReportOutcome out;
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<title>bouncefit report: " << HtmlEscape(dir.filename().string()) << "</title>\n"
    << "<style>\n" << ReportStyle() << "</style>\n</head>\n<body>\n"
    << "<h1>bouncefit report: " << clip_of_drop.size() << " drops, one fit</h1>\n"
    << "<p class=\"note\">Each drop's recorded rebound heights beside the fitted ball "
       "(OUT/coefficients.json) dropped from that drop's release. Heights in metres, the ball's "
       "bottom above the floor.</p>\n<h2>Drops</h2>\n<table>\n<tr><th>drop</th><th>clip</th>"
       "<th>release (m)</th><th>bounce</th><th>recorded (m)</th><th>simulated (m)</th>"
       "<th>simulated - recorded (mm)</th></tr>\n";
  for (const auto& r : rows) {
    // An unknown number (empty in drops.csv) leaves its cell empty.
    const double difference_mm = (r.simulated_m - r.recorded_m) * 1e3;
    h << "<tr><td>" << r.drop << "</td><td><a href=\"" << HtmlEscape(r.clip_dir) << "/report.html\">"
      << HtmlEscape(r.clip_dir) << "</a></td><td>"
      << (std::isfinite(r.release_m) ? fmt::format("{:.4f}", r.release_m) : "") << "</td><td>" << r.bounce
      << "</td><td>" << (std::isfinite(r.recorded_m) ? fmt::format("{:.4f}", r.recorded_m) : "") << "</td><td>"
      << (std::isfinite(r.simulated_m) ? fmt::format("{:.4f}", r.simulated_m) : "") << "</td><td>"
      << (std::isfinite(difference_mm) ? fmt::format("{:.1f}", difference_mm) : "") << "</td></tr>\n";
  }
  h << "</table>\n";

  // Each clip's own report draws its drop beside the simulation (height over time): embed that.
  for (const auto& [drop, clip] : clip_of_drop) {
    const ReportOutcome one = WriteReport(dir / clip, options);
    h << "<h2>Drop " << drop << ": " << HtmlEscape(clip) << "</h2>\n";
    for (const auto& f : one.figures) {
      if (f.id != "trajectory") continue;
      h << FigureHtml(f);
      out.figures.push_back(f);
    }
    for (const auto& s : one.skipped) out.skipped.push_back(clip + ": " + s);
  }
  h << "</body>\n</html>\n";

  out.html = dir / "report.html";
  WriteTextAtomically(out.html, h.str());
  return out;
}

}  // namespace bouncefit
