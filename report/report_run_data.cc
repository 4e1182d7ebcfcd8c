#include "report/report_run_data.h"

#include "msgs/frame_time.h"
#include "msgs/peaks_csv.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>


namespace bouncefit {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Fail(const fs::path& file, const std::string& what) {
  throw std::runtime_error(file.string() + ": " + what);
}

std::string ReadWholeFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) Fail(file, "cannot be read");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}


// A CSV with a header; columns looked up by name so that added columns do not break it.
class CsvTable {
 public:
  CsvTable(const fs::path& file, const std::vector<std::string>& required) : file_(file) {
    const std::string text = ReadWholeFile(file);
    // A run still writing may have left a last line half written: that line is ignored
    // when it is incomplete (no newline and too few fields).
    const bool open_end = !text.empty() && text.back() != '\n';
    std::istringstream in(text);
    std::string line;
    if (!std::getline(in, line)) Fail(file, "is empty (no header line)");
    const auto header = SplitCsvLine(line);
    for (size_t i = 0; i < header.size(); ++i) columns_[header[i]] = i;
    for (const auto& name : required) {
      if (!columns_.count(name)) Fail(file, "header lacks column '" + name + "'");
    }
    int line_no = 1;
    while (std::getline(in, line)) {
      ++line_no;
      if (line.empty() || line == "\r") continue;
      auto cells = SplitCsvLine(line);
      if (open_end && in.peek() == std::char_traits<char>::eof() && cells.size() < header.size()) {
        break;
      }
      if (cells.size() != header.size()) {
        Fail(file, "line " + std::to_string(line_no) + " has " + std::to_string(cells.size()) +
                       " fields, the header has " + std::to_string(header.size()));
      }
      rows_.push_back(std::move(cells));
      line_numbers_.push_back(line_no);
    }
  }

  size_t size() const { return rows_.size(); }
  bool Has(const std::string& column) const { return columns_.count(column) > 0; }

  // NaN for an empty cell or an absent optional column; garbage is an error.
  double Number(size_t row, const std::string& column) const {
    auto it = columns_.find(column);
    if (it == columns_.end()) return kReportNaN;
    const std::string& cell = rows_[row][it->second];
    if (cell.empty() || cell == "nan" || cell == "NaN") return kReportNaN;
    char* end = nullptr;
    const double v = std::strtod(cell.c_str(), &end);
    if (end == cell.c_str() || *end != '\0') {
      Fail(file_, "line " + std::to_string(line_numbers_[row]) + ": '" + cell +
                      "' in column " + column + " is not a number");
    }
    return v;
  }
  std::string Text(size_t row, const std::string& column) const {
    auto it = columns_.find(column);
    return it == columns_.end() ? "" : rows_[row][it->second];
  }
  double Required(size_t row, const std::string& column) const {
    const double v = Number(row, column);
    if (!std::isfinite(v)) {
      Fail(file_, "line " + std::to_string(line_numbers_[row]) + ": column " + column +
                      " is empty");
    }
    return v;
  }

 private:
  fs::path file_;
  std::map<std::string, size_t> columns_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<int> line_numbers_;
};

nlohmann::json ParseJson(const fs::path& file, const std::string& text) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    Fail(file, "is not valid JSON (" + what + ")");
  }
}

// JSON null (how NaN is written) and absent keys read as NaN.
double JsonNumber(const nlohmann::json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return kReportNaN;
  if (!it->is_number()) throw std::runtime_error(std::string("field '") + key + "' is not a number");
  return it->get<double>();
}

std::vector<double> JsonNumbers(const nlohmann::json& j, const char* key) {
  std::vector<double> out;
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return out;
  if (!it->is_array()) throw std::runtime_error(std::string("field '") + key + "' is not an array");
  for (const auto& v : *it) out.push_back(v.is_null() ? kReportNaN : v.get<double>());
  return out;
}

std::vector<ReportTrackRow> LoadTrack(const fs::path& file) {
  CsvTable csv(file, {"frame", "t_s", "found"});
  std::vector<ReportTrackRow> rows;
  rows.reserve(csv.size());
  for (size_t i = 0; i < csv.size(); ++i) {
    ReportTrackRow r;
    r.frame = static_cast<long>(csv.Required(i, "frame"));
    r.t_s = csv.Required(i, "t_s");
    r.found = csv.Required(i, "found") != 0;
    r.cx_px = csv.Number(i, "cx_px");
    r.cy_px = csv.Number(i, "cy_px");
    r.x_px = csv.Number(i, "x_px");
    r.y_px = csv.Number(i, "y_px");
    r.w_px = csv.Number(i, "w_px");
    r.h_px = csv.Number(i, "h_px");
    // A hand-held camera's motion taken out, as the detector did: the ball in the scene.
    const double camera_dx = csv.Number(i, "camera_dx_px"), camera_dy = csv.Number(i, "camera_dy_px");
    if (std::isfinite(camera_dx) && std::isfinite(camera_dy)) r.cx_px -= camera_dx, r.cy_px -= camera_dy;
    rows.push_back(r);
  }
  return rows;
}

std::vector<ReportPeak> LoadPeaks(const fs::path& file) {
  std::vector<ReportPeak> peaks;
  for (const PeaksCsvRow& r : ReadPeaksCsv(file)) {
    ReportPeak p;
    p.bounce = r.bounce;
    p.t_s = r.t_s;
    p.height_m = r.height_m;
    p.height_px = r.height_px;
    p.flight_height_m = r.flight_height_m;
    p.emitted_t_s = r.emitted_t_s;
    p.fused_height_m = r.fused_height_m;
    p.refit_height_m = r.refit_height_m;
    p.drop = r.drop;
    peaks.push_back(p);
  }
  return peaks;
}

std::vector<ReportSimSample> LoadSimulated(const fs::path& file) {
  CsvTable csv(file, {"t_s", "height_m"});
  std::vector<ReportSimSample> out;
  for (size_t i = 0; i < csv.size(); ++i) {
    const double drop = csv.Number(i, "drop");
    out.push_back({std::isfinite(drop) ? static_cast<int>(drop) : 0, csv.Required(i, "t_s"), csv.Required(i, "height_m")});
  }
  return out;
}

std::vector<ReportImpact> LoadImpacts(const fs::path& file) {
  CsvTable csv(file, {"t_s", "source"});
  std::vector<ReportImpact> out;
  for (size_t i = 0; i < csv.size(); ++i) out.push_back({csv.Required(i, "t_s"), csv.Text(i, "source")});
  return out;
}

std::vector<ReportWaveSample> LoadWaveform(const fs::path& file) {
  CsvTable csv(file, {"t_s", "peak"});
  std::vector<ReportWaveSample> out;
  for (size_t i = 0; i < csv.size(); ++i) out.push_back({csv.Required(i, "t_s"), csv.Required(i, "peak")});
  return out;
}

ReportCalibration LoadCalibration(const fs::path& file) {
  const auto j = ParseJson(file, ReadWholeFile(file));
  if (!j.is_object()) Fail(file, "is not a JSON object");
  ReportCalibration c;
  try {
    c.t_s = JsonNumber(j, "t_s");
    c.px_per_m = JsonNumber(j, "px_per_m");
    c.px_per_m_sigma = JsonNumber(j, "px_per_m_sigma");
    c.roll_rad = JsonNumber(j, "roll_rad");
    c.roll_sigma_rad = JsonNumber(j, "roll_sigma_rad");
    c.floor_px = JsonNumber(j, "floor_px");
    c.floor_sigma_px = JsonNumber(j, "floor_sigma_px");
    if (j.contains("method") && j["method"].is_string()) c.method = j["method"];
    const double samples = JsonNumber(j, "samples");
    c.samples = std::isfinite(samples) ? static_cast<int>(samples) : 0;
  } catch (const std::exception& e) {
    Fail(file, e.what());
  }
  if (!std::isfinite(c.px_per_m)) Fail(file, "has no px_per_m");
  return c;
}

ReportFit ParseFit(const nlohmann::json& j) {
  if (!j.is_object()) throw std::runtime_error("not a JSON object");
  ReportFit f;
  f.t_s = JsonNumber(j, "t_s");
  f.sequence = j.value("sequence", 0);
  f.after_bounce = j.value("after_bounce", 0);
  f.final = j.value("final", false);
  f.model = j.value("model", std::string());
  f.method = j.value("method", std::string());
  if (j.contains("coefficients")) {
    if (!j["coefficients"].is_array()) throw std::runtime_error("'coefficients' is not an array");
    for (const auto& c : j["coefficients"]) {
      ReportCoefficient rc;
      rc.name = c.at("name").get<std::string>();
      rc.value = JsonNumber(c, "value");
      rc.sigma = JsonNumber(c, "sigma");
      rc.identifiable = c.value("identifiable", true);
      f.coefficients.push_back(rc);
    }
  }
  f.recorded_m = JsonNumbers(j, "recorded_m");
  f.simulated_m = JsonNumbers(j, "simulated_m");
  f.residual_m = JsonNumber(j, "residual_m");
  const double evals = JsonNumber(j, "evaluations");
  f.evaluations = std::isfinite(evals) ? static_cast<long>(evals) : 0;
  f.wall_time_s = JsonNumber(j, "wall_time_s");
  f.time_step_s = JsonNumber(j, "time_step_s");
  const double iters = JsonNumber(j, "iterations");
  f.iterations = std::isfinite(iters) ? static_cast<int>(iters) : 0;
  return f;
}

std::vector<ReportFit> LoadFits(const fs::path& file) {
  std::istringstream in(ReadWholeFile(file));
  std::vector<ReportFit> fits;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      fits.push_back(ParseFit(nlohmann::json::parse(line)));
    } catch (const std::exception& e) {
      std::string what = e.what();
      std::replace(what.begin(), what.end(), '\n', ' ');
      Fail(file, "line " + std::to_string(line_no) + ": " + what);
    }
  }
  return fits;
}

}  // namespace

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  for (char c : line) {
    if (c == ',') {
      cells.push_back(cell);
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  cells.push_back(cell);
  return cells;
}

const ReportFit* ReportRunData::FinalFit() const {
  for (auto it = fits.rbegin(); it != fits.rend(); ++it) {
    if (it->final) return &*it;
  }
  return fits.empty() ? nullptr : &fits.back();
}

namespace {

// A run whose pictures were re-timed (summary.json clock.frames_retimed) reports its rows on
// the clock they were taken on; its track.csv keeps the stamps. The track is read on the same
// clock, so that the tracked curve meets the apexes.
// Slow motion in the stamps (clock.capture_clock): the rows are on the capture clock, every
// picture one capture period after the one before.
void RetimeTrack(const nlohmann::json& summary, std::vector<ReportTrackRow>* track) {
  if (!summary.is_object() || !summary.contains("clock") || !summary["clock"].is_object()) return;
  const auto& capture = summary["clock"].value("capture_clock", nlohmann::json());
  if (capture.is_object() && capture.value("capture_fps", 0.0) > 0) {
    const double fps = capture.value("capture_fps", 0.0);
    for (size_t i = 0; i < track->size(); ++i) (*track)[i].t_s = static_cast<double>(i) / fps;
    return;
  }
  const auto& r = summary["clock"].value("frames_retimed", nlohmann::json());
  if (!r.is_object()) return;
  const double f = r.value("source_fps", 0.0), c = r.value("phase", 0.0), first = r.value("first_frame_s", 0.0);
  if (!(f > 0) || !std::isfinite(c) || !std::isfinite(first)) return;
  for (auto& row : *track) row.t_s = TakenAtSeconds(first + row.t_s, f, c) - first;
}

// Every time on real seconds: a slow-motion file's rows are on its stamps, its heights and
// its simulation in real seconds.
void ReadOnRealTime(ReportRunData* run) {
  double k = kReportNaN;
  if (run->summary && run->summary->contains("clock") && (*run->summary)["clock"].is_object())
    k = JsonNumber((*run->summary)["clock"], "time_scale");
  if (!(k > 0) && run->coefficients_export) k = JsonNumber(*run->coefficients_export, "time_scale");
  if (!(k > 0) || k == 1) return;
  run->time_scale = k;
  for (auto& r : run->track) r.t_s *= k;
  for (auto& p : run->peaks) p.t_s *= k, p.emitted_t_s *= k;
  for (auto& s : run->simulated) s.t_s *= k;
  for (auto& i : run->impacts) i.t_s *= k;
  for (auto& w : run->waveform) w.t_s *= k;
  for (auto& f : run->fits) f.t_s *= k;
  if (run->calibration) run->calibration->t_s *= k;
}

}  // namespace

ReportRunData LoadRunDirectory(const fs::path& dir) {
  if (!fs::is_directory(dir)) {
    throw std::runtime_error(dir.string() + ": is not a directory");
  }
  ReportRunData run;
  run.dir = dir;
  const fs::path track = dir / "track.csv";
  if (!fs::exists(track)) Fail(track, "is missing (is this a `bouncefit run --out` directory?)");
  run.track = LoadTrack(track);

  auto optional = [&](const char* name) -> std::optional<fs::path> {
    const fs::path p = dir / name;
    if (fs::exists(p)) return p;
    run.absent_files.push_back(name);
    return std::nullopt;
  };
  if (auto p = optional("peaks.csv")) run.peaks = LoadPeaks(*p);
  if (auto p = optional("calibration.json")) run.calibration = LoadCalibration(*p);
  if (auto p = optional("fit.jsonl")) run.fits = LoadFits(*p);
  if (auto p = optional("simulated.csv")) run.simulated = LoadSimulated(*p);
  // The sound's files (absent with --no-audio and in runs written without them: nothing to say).
  if (fs::exists(dir / "impacts.csv")) run.impacts = LoadImpacts(dir / "impacts.csv");
  if (fs::exists(dir / "waveform.csv")) run.waveform = LoadWaveform(dir / "waveform.csv");
  if (auto p = optional("summary.json")) run.summary = ParseJson(*p, ReadWholeFile(*p));
  if (run.summary) RetimeTrack(*run.summary, &run.track);
  // waveform.csv is on the sound's own clock; the detect node found its offset from the picture.
  if (run.summary && run.summary->contains("sound")) {
    const auto& sound = (*run.summary)["sound"];
    if (sound.value("used", false) && sound.contains("offset_s") && sound["offset_s"].is_number())
      for (auto& w : run.waveform) w.t_s -= sound["offset_s"].get<double>();
  }
  if (auto p = optional("coefficients.json")) {
    run.coefficients_export = ParseJson(*p, ReadWholeFile(*p));
  }
  // The fit's export for Bullet users: the fitted_ball project's README (fit/fit_export.h),
  // or the C++ snippet older runs wrote.
  for (const char* name : {"fitted_ball/README.md", "soft_body_config.cc", "fit_export.cc"}) {
    if (fs::exists(dir / name)) {
      run.fit_export_cc = ReadWholeFile(dir / name);
      run.fit_export_cc_name = name;
      break;
    }
  }
  if (run.fit_export_cc_name.empty()) run.absent_files.push_back("fitted_ball/README.md");
  ReadOnRealTime(&run);
  return run;
}

std::map<std::pair<int, int>, ReportFitPair> FinalFitByBounce(const ReportRunData& run) {
  std::map<std::pair<int, int>, ReportFitPair> out;
  const nlohmann::json* c = run.coefficients_export ? &*run.coefficients_export : nullptr;
  try {
    if (c && c->contains("drops") && (*c)["drops"].is_array()) {
      for (const auto& d : (*c)["drops"]) {
        const auto bounces = d.value("bounces", std::vector<int>());
        const auto rec = JsonNumbers(d, "recorded_m"), sim = JsonNumbers(d, "simulated_m");
        for (size_t i = 0; i < bounces.size(); ++i)
          out[{d.value("drop", 0), bounces[i]}] = {i < rec.size() ? rec[i] : kReportNaN,
                                                   i < sim.size() ? sim[i] : kReportNaN};
      }
      return out;
    }
  } catch (const std::exception& e) {
    Fail(run.dir / "coefficients.json", std::string("drops: ") + e.what());
  }
  // An older run: the fit's own drop only, the last of peaks.csv, from its start apex.
  const ReportFit* fit = run.FinalFit();
  if (!fit) return out;
  const int start = c ? c->value("start_bounce", 0) : 0;
  const int drop = run.peaks.empty() ? 0 : run.peaks.back().drop;
  const size_t own = fit->simulated_m.size();
  for (size_t i = 0; i < own && i < fit->recorded_m.size(); ++i)
    out[{drop, start + 1 + static_cast<int>(i)}] = {fit->recorded_m[i], fit->simulated_m[i]};
  return out;
}

double BallBottomHeightM(double cx_px, double cy_px, double h_px,
                         const ReportCalibration& c) {
  if (!c.usable() || !std::isfinite(cx_px) || !std::isfinite(cy_px) || !std::isfinite(h_px)) {
    return kReportNaN;
  }
  const double roll = std::isfinite(c.roll_rad) ? c.roll_rad : 0.0;
  const double along_down = cx_px * std::sin(roll) + cy_px * std::cos(roll) + 0.5 * h_px;
  return (c.floor_px - along_down) / c.px_per_m;
}

double BallBottomHeightM(const ReportTrackRow& row, const ReportCalibration& c) {
  if (!row.found) return kReportNaN;
  return BallBottomHeightM(row.cx_px, row.cy_px, row.h_px, c);
}

double ApexHeightSigmaM(double height_m, const ReportCalibration& c) {
  if (!c.usable() || !std::isfinite(height_m)) return kReportNaN;
  const double scale_rel = std::isfinite(c.px_per_m_sigma) ? c.px_per_m_sigma / c.px_per_m : 0;
  const double floor_m = std::isfinite(c.floor_sigma_px) ? c.floor_sigma_px / c.px_per_m : 0;
  const double pixel_m = 0.5 / c.px_per_m;
  return std::sqrt(std::pow(height_m * scale_rel, 2) + floor_m * floor_m + pixel_m * pixel_m);
}

double ReportPeak::HeightToUse() const {
  return std::isfinite(fused_height_m) ? fused_height_m : height_m;
}

std::vector<double> RestitutionFromHeights(const std::vector<ReportPeak>& peaks) {
  std::vector<double> e(peaks.size(), kReportNaN);
  for (size_t i = 1; i < peaks.size(); ++i) {
    const double a = peaks[i - 1].HeightToUse(), b = peaks[i].HeightToUse();
    if (peaks[i].bounce == peaks[i - 1].bounce + 1 && a > 0 && b >= 0) e[i] = std::sqrt(b / a);
  }
  return e;
}

std::vector<double> RestitutionFromFlights(const std::vector<ReportPeak>& peaks) {
  std::vector<double> e(peaks.size(), kReportNaN);
  for (size_t i = 1; i < peaks.size(); ++i) {
    const auto& a = peaks[i - 1];
    const auto& b = peaks[i];
    if (b.bounce == a.bounce + 1 && a.flight_height_m > 0 && b.flight_height_m >= 0) {
      e[i] = std::sqrt(b.flight_height_m / a.flight_height_m);
    }
  }
  return e;
}

}  // namespace bouncefit
