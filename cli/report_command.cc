// bouncefit report DIR: report.html and PNG figures from a run's output directory.
#include <cstdio>

#include "cli/commands.h"
#include "cli/number_checks.h"
#include "report/report_drops.h"
#include "report/report_html.h"

namespace bouncefit::cli {

void AddReportCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "report", "Write report.html and figures from a run's output directory");
  struct Flags {
    std::string dir;
    bool quiet = false;
    ReportOptions options;
  };
  auto flags = std::make_shared<Flags>();
  cmd->add_option("DIR", flags->dir, "Output directory of `bouncefit run --out DIR` (one clip or several)")
      ->required();
  cmd->add_option("--gnuplot", flags->options.figures.gnuplot.executable,
                  "gnuplot executable (Debian package gnuplot-nox)")
      ->capture_default_str();
  cmd->add_option("--plot-timeout", flags->options.figures.gnuplot.timeout_s,
                  "Seconds a figure may take before gnuplot is killed")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--width", flags->options.figures.width_px, "Figure width, pixels")
      ->capture_default_str()
      ->check(CLI::Range(300, 4000));
  cmd->add_flag("--quiet,-q", flags->quiet, "Print nothing on success");
  cmd->footer("Example (after `bouncefit run --out out/sample`; then open out/sample/report.html):\n"
              "  bouncefit report out/sample");
  cmd->callback([flags] {
    // `run a.mp4 b.mp4 --out DIR` leaves one directory per clip and the joint fit's drops.csv.
    const ReportOutcome out = IsSeveralClipsDirectory(flags->dir)
                                  ? WriteSeveralClipsReport(flags->dir, flags->options)
                                  : WriteReport(flags->dir, flags->options);
    if (flags->quiet) return;
    std::printf("report: %s (%zu figures", out.html.c_str(), out.figures.size());
    if (!out.skipped.empty()) std::printf(", %zu not drawn", out.skipped.size());
    std::printf(")\n");
    for (const auto& f : out.figures) std::printf("  figure %s\n", f.png.c_str());
    for (const auto& s : out.skipped) std::printf("  not drawn: %s\n", s.c_str());
  });
}

}  // namespace bouncefit::cli
