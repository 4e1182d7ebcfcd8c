#pragma once
// The report's figures: for each, a data file and a gnuplot script under
// <out>/report_plots/ (kept, so a user can restyle a figure and rerun gnuplot), and the
// PNG <out>/report_<id>.png drawn by gnuplot's pngcairo terminal.
#include <filesystem>
#include <string>
#include <vector>

#include "report/report_gnuplot.h"
#include "report/report_run_data.h"

namespace bouncefit {

struct ReportFigure {
  std::string id;       // "height", "trajectory", "bounces", "coefficients", "aspect"
  std::string title;
  std::string caption;  // what is plotted, with units
  std::filesystem::path png;
};

struct ReportFigureOptions {
  int width_px = 1100;
  int height_px = 480;
  GnuplotOptions gnuplot;
};

// Draws every figure the run's files allow. A figure whose inputs are absent is not drawn;
// its reason goes to *skipped ("trajectory: simulated.csv absent"). Throws on a gnuplot
// failure.
std::vector<ReportFigure> WriteReportFigures(const ReportRunData& run,
                                             const std::filesystem::path& out_dir,
                                             const ReportFigureOptions& options,
                                             std::vector<std::string>* skipped);

}  // namespace bouncefit
