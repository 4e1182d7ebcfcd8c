#pragma once
// report.html: one self-contained page (inline CSS, PNGs as base64 data URIs, no network)
// with the figures and the tables of a run, and the whole report entry point.
#include <filesystem>
#include <string>
#include <vector>

#include "report/report_figures.h"
#include "report/report_run_data.h"

namespace bouncefit {

std::string Base64Encode(const std::string& bytes);
std::string HtmlEscape(const std::string& text);
// The pages' stylesheet (inline CSS), shared by a run's report and a several-clip report.
std::string ReportStyle();
std::string ReadBinary(const std::filesystem::path& file);
// One figure as an embedded <figure> (its PNG as a data URI, title and caption).
std::string FigureHtml(const ReportFigure& f);
// Writes `file` through a temporary beside it, so a reader never sees half a page.
void WriteTextAtomically(const std::filesystem::path& file, const std::string& text);

// The page as a string. Figures are read from their PNG files and embedded.
std::string RenderReportHtml(const ReportRunData& run, const std::vector<ReportFigure>& figures,
                             const std::vector<std::string>& skipped);

struct ReportOptions {
  ReportFigureOptions figures;
};

struct ReportOutcome {
  std::filesystem::path html;
  std::vector<ReportFigure> figures;
  std::vector<std::string> skipped;  // figures not drawn, with the reason
  ReportRunData run;
};

// Reads `dir`, draws the figures into it, writes dir/report.html. Throws
// std::runtime_error with a one-line message naming the file at fault.
ReportOutcome WriteReport(const std::filesystem::path& dir, const ReportOptions& options);

}  // namespace bouncefit
