#include "report/report_html.h"

#include <fmt/format.h>

#include "report/report_3d.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bouncefit {
namespace {

namespace fs = std::filesystem;

// A number the run does not know (NaN, JSON null) shows as a dash.
constexpr const char* kUnknown = "&ndash;";

// A coefficient's entry in the fit export (coefficients.json), if there is one: either
// {"coefficients": {name: {...}}} (fit/fit_export.h) or a list of {"name": ...}.
const nlohmann::json* ExportEntry(const ReportRunData& run, const std::string& name) {
  if (!run.coefficients_export || !run.coefficients_export->is_object()) return nullptr;
  const auto& j = *run.coefficients_export;
  if (!j.contains("coefficients")) return nullptr;
  const auto& c = j["coefficients"];
  if (c.is_object() && c.contains(name) && c[name].is_object()) return &c[name];
  if (c.is_array()) {
    for (const auto& e : c) {
      if (e.is_object() && e.value("name", std::string()) == name) return &e;
    }
  }
  return nullptr;
}

// The unit as the export records it: "-" for dimensionless, "" when not recorded.
std::string CoefficientUnit(const ReportRunData& run, const std::string& name) {
  const auto* e = ExportEntry(run, name);
  if (!e || !e->contains("unit") || !(*e)["unit"].is_string()) return "";
  const std::string unit = (*e)["unit"].get<std::string>();
  return unit.empty() ? "-" : unit;
}

std::string CoefficientNote(const ReportRunData& run, const std::string& name) {
  const auto* e = ExportEntry(run, name);
  if (!e || !e->contains("note") || !(*e)["note"].is_string()) return "";
  return (*e)["note"].get<std::string>();
}

void Row(std::ostringstream& h, std::initializer_list<std::string> cells) {
  h << "<tr>";
  for (const auto& c : cells) h << "<td>" << c << "</td>";
  h << "</tr>\n";
}

void Header(std::ostringstream& h, std::initializer_list<std::string> cells) {
  h << "<tr>";
  for (const auto& c : cells) h << "<th>" << c << "</th>";
  h << "</tr>\n";
}

void SummarySection(std::ostringstream& h, const ReportRunData& run) {
  h << "<h2>Run</h2>\n<table class=\"kv\">\n";
  Row(h, {"directory", HtmlEscape(fs::absolute(run.dir).string())});
  const auto found = std::count_if(run.track.begin(), run.track.end(),
                                   [](const auto& r) { return r.found; });
  Row(h, {"frames tracked", std::to_string(run.track.size()) + " frames, ball found in " +
                                std::to_string(found)});
  if (!run.track.empty()) {
    Row(h, {"stream duration", fmt::format("{:.3f} s", run.track.back().t_s - run.track.front().t_s)});
  }
  if (run.summary && run.summary->is_object()) {
    const auto& s = *run.summary;
    if (s.contains("input") && s["input"].is_string()) Row(h, {"input", HtmlEscape(s["input"])});
    if (s.contains("ball") && s["ball"].is_string()) Row(h, {"ball", HtmlEscape(s["ball"])});
    if (s.contains("dropped_frames") && s["dropped_frames"].is_number()) {
      Row(h, {"dropped frames", std::to_string(s["dropped_frames"].get<long>()) + " frames"});
    }
    if (s.contains("wall_time_s") && s["wall_time_s"].is_number()) {
      Row(h, {"wall time", fmt::format("{:.2f} s", s["wall_time_s"].get<double>())});
    }
    if (s.contains("timings_ms") && s["timings_ms"].is_object()) {
      std::string t;
      for (const auto& [k, v] : s["timings_ms"].items()) {
        if (!v.is_number()) continue;
        if (!t.empty()) t += ", ";
        t += fmt::format("{} {:.1f} ms", HtmlEscape(k), v.get<double>());
      }
      if (!t.empty()) Row(h, {"time spent", t});
    }
  }
  h << "</table>\n";
}

void CalibrationSection(std::ostringstream& h, const ReportRunData& run) {
  h << "<h2>Calibration</h2>\n";
  if (!run.calibration) {
    h << "<p class=\"note\">No calibration.json: heights are shown in pixels only.</p>\n";
    return;
  }
  const auto& c = *run.calibration;
  h << "<table class=\"kv\">\n";
  Header(h, {"quantity", "value", "standard uncertainty", "unit"});
  const double roll_deg = c.roll_rad * 180 / M_PI, roll_sigma_deg = c.roll_sigma_rad * 180 / M_PI;
  Row(h, {"image scale", std::isfinite(c.px_per_m) ? fmt::format("{:.2f}", c.px_per_m) : kUnknown,
          std::isfinite(c.px_per_m_sigma) ? fmt::format("{:.2f}", c.px_per_m_sigma) : kUnknown, "px/m"});
  Row(h, {"camera roll", std::isfinite(roll_deg) ? fmt::format("{:.3f}", roll_deg) : kUnknown,
          std::isfinite(roll_sigma_deg) ? fmt::format("{:.3f}", roll_sigma_deg) : kUnknown, "deg"});
  Row(h, {"floor line", std::isfinite(c.floor_px) ? fmt::format("{:.2f}", c.floor_px) : kUnknown,
          std::isfinite(c.floor_sigma_px) ? fmt::format("{:.2f}", c.floor_sigma_px) : kUnknown, "px"});
  Row(h, {"method", HtmlEscape(c.method), "", ""});
  Row(h, {"frames used", std::to_string(c.samples), "", "frames"});
  Row(h, {"known at", std::isfinite(c.t_s) ? fmt::format("{:.3f}", c.t_s) : kUnknown, "", "s"});
  h << "</table>\n";
}

void PeaksSection(std::ostringstream& h, const ReportRunData& run) {
  h << "<h2>Bounces</h2>\n";
  if (run.peaks.empty()) {
    h << "<p class=\"note\">No bounce apex detected (peaks.csv "
      << (std::count(run.absent_files.begin(), run.absent_files.end(), "peaks.csv") ? "absent"
                                                                                  : "empty")
      << ").</p>\n";
    return;
  }
  const auto e_h = RestitutionFromHeights(run.peaks);
  const auto e_f = RestitutionFromFlights(run.peaks);
  const auto fitted = FinalFitByBounce(run);
  bool several = false;
  for (const auto& p : run.peaks) several = several || p.drop != run.peaks.front().drop;
  h << "<table>\n";
  Header(h, {several ? "drop:bounce" : "bounce", run.time_scale == 1 ? "apex time (s)" : "apex time (real s)", "height (m)", "&plusmn; (m)", "height (px)",
             "refitted height (m)", "flight-time height (m)", "restitution from heights (-)",
             "restitution from flights (-)", "simulated (m)", "emitted after apex (ms)"});
  for (size_t i = 0; i < run.peaks.size(); ++i) {
    const auto& p = run.peaks[i];
    double sigma = p.height_sigma_m;
    if (!std::isfinite(sigma) && run.calibration) sigma = ApexHeightSigmaM(p.height_m, *run.calibration);
    const auto it = fitted.find({p.drop, p.bounce});  // by its number, as the fit took it
    const double sim = it == fitted.end() ? kReportNaN : it->second.simulated_m;
    const double emitted_ms = (p.emitted_t_s - p.t_s) * 1000;
    Row(h, {(several ? std::to_string(p.drop) + ":" : "") + std::to_string(p.bounce) + (p.bounce == 0 ? " (release)" : ""),
            std::isfinite(p.t_s) ? fmt::format("{:.4f}", p.t_s) : kUnknown,
            std::isfinite(p.height_m) ? fmt::format("{:.4f}", p.height_m) : kUnknown,
            std::isfinite(sigma) ? fmt::format("{:.4f}", sigma) : kUnknown,
            std::isfinite(p.height_px) ? fmt::format("{:.1f}", p.height_px) : kUnknown,
            std::isfinite(p.refit_height_m) ? fmt::format("{:.4f}", p.refit_height_m) : kUnknown,
            std::isfinite(p.flight_height_m) ? fmt::format("{:.4f}", p.flight_height_m) : kUnknown,
            std::isfinite(e_h[i]) ? fmt::format("{:.3f}", e_h[i]) : kUnknown,
            std::isfinite(e_f[i]) ? fmt::format("{:.3f}", e_f[i]) : kUnknown,
            std::isfinite(sim) ? fmt::format("{:.4f}", sim) : kUnknown,
            std::isfinite(emitted_ms) ? fmt::format("{:.0f}", emitted_ms) : kUnknown});
  }
  h << "</table>\n<p class=\"note\">Height: as emitted live; refitted: with every arc of its "
       "drop once the drop ended, over the floor where its own contacts are (the height to "
       "quote). Restitution e = sqrt(h<sub>i</sub>/h<sub>i-1</sub>); "
       "&plusmn; is one standard uncertainty (from peaks.csv, else from the calibration's "
       "scale and floor uncertainties and half a pixel).</p>\n";
}

void FitSection(std::ostringstream& h, const ReportRunData& run) {
  h << "<h2>Fitted coefficients</h2>\n";
  const ReportFit* fit = run.FinalFit();
  if (!fit) {
    h << "<p class=\"note\">No fit yet (fit.jsonl "
      << (std::count(run.absent_files.begin(), run.absent_files.end(), "fit.jsonl") ? "absent"
                                                                                  : "empty")
      << ").</p>\n";
    return;
  }
  h << "<p>" << (fit->final ? "Final fit" : "Latest fit (not final)") << " after bounce "
    << fit->after_bounce << ": model <b>" << HtmlEscape(fit->model) << "</b>, search <b>"
    << HtmlEscape(fit->method) << "</b>.</p>\n<table>\n";
  Header(h, {"coefficient", "value", "standard uncertainty", "unit", "identifiable", "note"});
  bool unknown_unit = false;
  for (const auto& c : fit->coefficients) {
    std::string unit = CoefficientUnit(run, c.name);
    if (unit.empty()) {
      unit = "&ndash;*";
      unknown_unit = true;
    } else {
      unit = HtmlEscape(unit);
    }
    Row(h, {"<code>" + HtmlEscape(c.name) + "</code>", std::isfinite(c.value) ? fmt::format("{:.6g}", c.value) : kUnknown,
            std::isfinite(c.sigma) ? fmt::format("{:.3g}", c.sigma) : kUnknown, unit,
            c.identifiable ? "yes" : "<b>no</b>",
            "<span class=\"left\">" + HtmlEscape(CoefficientNote(run, c.name)) + "</span>"});
  }
  h << "</table>\n";
  if (unknown_unit) {
    h << "<p class=\"note\">* unit not recorded in fit.jsonl: dimensionless or in the model's "
         "own units (see the model's coefficient list in <code>bouncefit fit --help</code>).</p>\n";
  }
  h << "<table class=\"kv\">\n";
  Row(h, {"RMS residual of bounce heights",
          (std::isfinite(fit->residual_m) ? fmt::format("{:.2f}", fit->residual_m * 1000) : kUnknown) + " mm"});
  Row(h, {"simulations run", std::to_string(fit->evaluations)});
  Row(h, {"time spent", (std::isfinite(fit->wall_time_s) ? fmt::format("{:.2f}", fit->wall_time_s) : kUnknown) + " s"});
  Row(h, {"simulation time step (coefficients hold for it)",
          (std::isfinite(fit->time_step_s) ? fmt::format("{:.5g}", fit->time_step_s * 1000) : kUnknown) + " ms"});
  Row(h, {"solver iterations (coefficients hold for them)", std::to_string(fit->iterations)});
  h << "</table>\n";

  if (run.fits.size() > 1) {
    h << "<h3>Fit history</h3>\n<table>\n";
    Header(h, {"after bounce", "model", "search", "final", "residual (mm)", "simulations",
               "time (s)"});
    for (const auto& f : run.fits) {
      Row(h, {std::to_string(f.after_bounce), HtmlEscape(f.model), HtmlEscape(f.method),
              f.final ? "yes" : "", std::isfinite(f.residual_m) ? fmt::format("{:.2f}", f.residual_m * 1000) : kUnknown,
              std::to_string(f.evaluations),
              std::isfinite(f.wall_time_s) ? fmt::format("{:.2f}", f.wall_time_s) : kUnknown});
    }
    h << "</table>\n";
  }
}

void ExportSection(std::ostringstream& h, const ReportRunData& run) {
  if (run.fit_export_cc.empty() && !run.coefficients_export) return;
  h << "<h2>Exports</h2>\n";
  if (!run.fit_export_cc.empty()) {
    h << "<h3>" << HtmlEscape(run.fit_export_cc_name)
      << ": the coefficients for your Bullet code</h3>\n<pre>"
      << HtmlEscape(run.fit_export_cc) << "</pre>\n";
  }
  if (run.coefficients_export) {
    h << "<h3>coefficients.json</h3>\n<pre>" << HtmlEscape(run.coefficients_export->dump(2))
      << "</pre>\n";
  }
}

}  // namespace

std::string ReadBinary(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string Base64Encode(const std::string& bytes) {
  static const char* kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string FigureHtml(const ReportFigure& f) {
  std::ostringstream h;
  h << "<figure id=\"fig-" << f.id << "\">\n<img class=\"figure\" alt=\"" << HtmlEscape(f.title)
    << "\" src=\"data:image/png;base64," << Base64Encode(ReadBinary(f.png)) << "\">\n"
    << "<figcaption><b>" << HtmlEscape(f.title) << ".</b> " << HtmlEscape(f.caption)
    << "</figcaption>\n</figure>\n";
  return h.str();
}

void WriteTextAtomically(const std::filesystem::path& file, const std::string& text) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    if (!f) throw std::runtime_error(tmp.string() + ": cannot be written");
  }
  std::filesystem::rename(tmp, file);
}

std::string ReportStyle() {
  return
       "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;margin:24px auto;"
       "max-width:1140px;color:#222;line-height:1.4}\n"
       "h1{font-size:1.6em;margin-bottom:0}h2{border-bottom:1px solid #ccc;margin-top:1.6em}\n"
       "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccc;"
       "padding:3px 8px;text-align:right}th{background:#f0f0f0}"
       "table.kv td:first-child{text-align:left}td code{white-space:nowrap}\n"
       "figure{margin:16px 0}figure img{max-width:100%;border:1px solid #ddd}"
       "figcaption{color:#444;font-size:.92em}\n"
       ".left{display:block;text-align:left}"
       "pre{background:#f6f6f6;padding:8px;overflow-x:auto;font-size:.88em}"
       ".note{color:#555;font-size:.92em}\n"
       ".view3d-row{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}"
       ".view3d{width:540px}.view3d canvas{width:540px;height:440px;border:1px solid #ddd}"
       ".view3d-controls input{width:300px;vertical-align:middle}"
       ".view3d-row figure{flex:1;min-width:300px;margin:0}\n";
}

std::string RenderReportHtml(const ReportRunData& run, const std::vector<ReportFigure>& figures,
                             const std::vector<std::string>& skipped) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<title>bouncefit report: " << HtmlEscape(run.dir.filename().string()) << "</title>\n"
    << "<style>\n" << ReportStyle()
    << "</style>\n</head>\n<body>\n"
    << "<h1>bouncefit report</h1>\n<p class=\"note\">Heights are the ball's bottom above the "
       "floor along true vertical; times are seconds since the first frame.</p>\n";
  SummarySection(h, run);
  std::string height_figure;
  for (const auto& f : figures)
    if (f.id == "height") height_figure = FigureHtml(f);
  h << View3dSection(run.dir, height_figure);

  h << "<h2>Figures</h2>\n";
  for (const auto& f : figures) h << FigureHtml(f);
  if (!skipped.empty()) {
    h << "<p class=\"note\">Not drawn:</p><ul class=\"note\">\n";
    for (const auto& s : skipped) h << "<li>" << HtmlEscape(s) << "</li>\n";
    h << "</ul>\n";
  }
  CalibrationSection(h, run);
  PeaksSection(h, run);
  FitSection(h, run);
  ExportSection(h, run);
  if (!run.absent_files.empty()) {
    std::string absent;
    for (const auto& f : run.absent_files) absent += (absent.empty() ? "" : ", ") + f;
    h << "<p class=\"note\">Files not present in the run directory: " << HtmlEscape(absent)
      << ".</p>\n";
  }
  // Says in the page itself whether every figure decoded (read by the headless check).
  h << "<p id=\"figure-status\" class=\"note\">" << figures.size() << " figures.</p>\n"
    << "<script>\nwindow.addEventListener('load', function () {\n"
       "  var imgs = document.querySelectorAll('img.figure'), ok = 0;\n"
       "  for (var i = 0; i < imgs.length; i++) if (imgs[i].complete && imgs[i].naturalWidth > 0) ok++;\n"
       "  var s = document.getElementById('figure-status');\n"
       "  s.setAttribute('data-decoded', ok); s.setAttribute('data-total', imgs.length);\n"
       "  s.textContent = ok + ' of ' + imgs.length + ' figures rendered.';\n"
       "});\n</script>\n"
    << "</body>\n</html>\n";
  return h.str();
}

ReportOutcome WriteReport(const fs::path& dir, const ReportOptions& options) {
  ReportOutcome out;
  out.run = LoadRunDirectory(dir);
  out.figures = WriteReportFigures(out.run, dir, options.figures, &out.skipped);
  out.html = dir / "report.html";
  WriteTextAtomically(out.html, RenderReportHtml(out.run, out.figures, out.skipped));
  return out;
}

}  // namespace bouncefit
