#pragma once
// A run's output directory (docs/FORMATS.md) read back into memory, for `bouncefit report`
// and for anything else that looks at a finished run.
//
// Only track.csv is required. Every other file may be absent (a run stopped before its
// first fit still reports what it has); a file that is present but garbled is an error.
// Errors are std::runtime_error with one line naming the file (and the line number).
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace bouncefit {

// The cells of one CSV line (no quoting in our files; a trailing comma is an empty last cell).
std::vector<std::string> SplitCsvLine(const std::string& line);

inline constexpr double kReportNaN = std::numeric_limits<double>::quiet_NaN();

struct ReportTrackRow {
  long frame = 0;
  double t_s = 0;
  bool found = false;
  double cx_px = kReportNaN, cy_px = kReportNaN;  // in the scene: a held camera's motion taken out
  double x_px = kReportNaN, y_px = kReportNaN, w_px = kReportNaN, h_px = kReportNaN;
};

struct ReportPeak {
  int bounce = 0;
  int drop = 0;  // peaks.csv's drop (0 in a file without the column)
  double t_s = 0;
  double height_m = kReportNaN;
  double height_px = kReportNaN;
  double flight_height_m = kReportNaN;  // NaN: unknown
  double emitted_t_s = kReportNaN;
  double height_sigma_m = kReportNaN;   // optional column; NaN when the file lacks it
  // Optional columns run writes at the end (NaN when the file lacks them): the height refitted
  // with every arc of its drop, and the height to use (heard end to end, its flight-time
  // height; else the refitted one; else the live one), which the final fit took.
  double refit_height_m = kReportNaN;
  double fused_height_m = kReportNaN;
  // fused_height_m, or the live height of a file without it.
  double HeightToUse() const;
};

struct ReportCalibration {
  double t_s = kReportNaN;
  double px_per_m = kReportNaN, px_per_m_sigma = kReportNaN;
  double roll_rad = kReportNaN, roll_sigma_rad = kReportNaN;
  double floor_px = kReportNaN, floor_sigma_px = kReportNaN;
  std::string method;
  int samples = 0;
  bool usable() const {
    return std::isfinite(px_per_m) && px_per_m > 0 && std::isfinite(floor_px);
  }
};

struct ReportCoefficient {
  std::string name;
  double value = kReportNaN;
  double sigma = kReportNaN;
  bool identifiable = true;
};

struct ReportFit {
  double t_s = kReportNaN;
  int sequence = 0;
  int after_bounce = 0;
  bool final = false;
  std::string model, method;
  std::vector<ReportCoefficient> coefficients;
  std::vector<double> recorded_m, simulated_m;
  double residual_m = kReportNaN;
  long evaluations = 0;
  double wall_time_s = kReportNaN;
  double time_step_s = kReportNaN;
  int iterations = 0;
};

// impacts.csv: an impact heard, seen or both.
struct ReportImpact {
  double t_s = 0;
  std::string source;  // "audio", "video" or "both"
};

// waveform.csv: the sound's peak |amplitude| (full scale 1) over a short window.
struct ReportWaveSample {
  double t_s = 0;
  double peak = 0;
};

struct ReportSimSample {
  int drop = 0;  // simulated.csv's drop (0 in a file without the column)
  double t_s = 0;
  double height_m = 0;
};

// The final fit's heights of one bounce: the recorded one it fitted and its simulation's.
struct ReportFitPair {
  double recorded_m = kReportNaN, simulated_m = kReportNaN;
};

struct ReportRunData {
  std::filesystem::path dir;
  std::vector<ReportTrackRow> track;
  std::vector<ReportPeak> peaks;
  std::optional<ReportCalibration> calibration;
  std::vector<ReportFit> fits;                // in file order
  std::vector<ReportSimSample> simulated;     // simulated.csv, empty when absent
  std::vector<ReportImpact> impacts;          // impacts.csv, empty when absent
  std::vector<ReportWaveSample> waveform;     // waveform.csv, empty when absent (no sound)
  std::optional<nlohmann::json> summary;      // summary.json
  std::optional<nlohmann::json> coefficients_export;  // coefficients.json
  std::string fit_export_cc;                  // the export's text for Bullet users, "" when absent
  std::string fit_export_cc_name;             // its file: fitted_ball/README.md (older runs:
                                              // soft_body_config.cc or fit_export.cc)
  std::vector<std::string> absent_files;      // optional files that were not there
  // Real seconds per second of the run's clock (summary.json's clock.time_scale, else
  // coefficients.json's): below 1 for a slow-motion file read on its stamps. Every time above
  // is read in real seconds (multiplied by it), so the tracked ball, its apexes and the
  // simulated one share the clock the heights were measured on.
  double time_scale = 1;

  // The last fit marked final, else the last fit, else null.
  const ReportFit* FinalFit() const;
};

// The final fit's heights by (drop, bounce) as peaks.csv numbers them: coefficients.json's
// drops; an older run's coefficients.json without them, its own drop (the last) from its
// start_bounce. Empty without a final fit.
std::map<std::pair<int, int>, ReportFitPair> FinalFitByBounce(const ReportRunData& run);

// Reads every file of docs/FORMATS.md that `report` uses from `dir`.
ReportRunData LoadRunDirectory(const std::filesystem::path& dir);

// Height of the ball's bottom above the floor (metres) from a tracked box and the
// calibration: the box centre projected on true down (roll_rad measured from image +y
// toward +x), plus half the box height, against the floor line. NaN if not computable.
double BallBottomHeightM(const ReportTrackRow& row, const ReportCalibration& calibration);
double BallBottomHeightM(double cx_px, double cy_px, double h_px,
                         const ReportCalibration& calibration);

// Standard uncertainty of an apex height (metres) from the calibration's uncertainties
// (scale and floor line) and half a pixel of box quantisation; used when peaks.csv has no
// height_sigma_m column.
double ApexHeightSigmaM(double height_m, const ReportCalibration& calibration);

// Restitution between consecutive apexes of one drop: sqrt(h_i / h_(i-1)) of the heights to
// use (ReportPeak::HeightToUse); NaN for
// bounce 0 or when the previous apex is missing.
std::vector<double> RestitutionFromHeights(const std::vector<ReportPeak>& peaks);
// The same from flight heights (impact-to-impact times), NaN where unknown.
std::vector<double> RestitutionFromFlights(const std::vector<ReportPeak>& peaks);

}  // namespace bouncefit
