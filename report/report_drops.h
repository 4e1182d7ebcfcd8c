#pragma once
// The report of `bouncefit run a.mp4 b.mp4 --out OUT` (several clips of one ball fitted
// jointly): each clip's own report (its drop beside the fitted ball dropped from the same
// release), and OUT/report.html with every drop's recorded and simulated heights.
#include <filesystem>

#include "report/report_html.h"

namespace bouncefit {

// Whether `dir` holds a several-clip run (OUT/drops.csv, no track.csv of its own).
bool IsSeveralClipsDirectory(const std::filesystem::path& dir);

// Writes each clip directory's report, then dir/report.html. Throws std::runtime_error with
// a one-line message naming the file at fault.
ReportOutcome WriteSeveralClipsReport(const std::filesystem::path& dir, const ReportOptions& options);

}  // namespace bouncefit
