#include "report/report_figures.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace bouncefit {
namespace {

namespace fs = std::filesystem;

// gnuplot data: numbers as "{:.9g}"; "?" marks a missing value (set datafile missing "?").
constexpr const char* kMissing = "?";

// A gnuplot string literal in single quotes (where only '' needs escaping).
std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "''";
    else if (c != '\n') out += c;
  }
  return out + "'";
}

void WriteText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error(file.string() + ": cannot be written");
}

class FigureWriter {
 public:
  FigureWriter(const fs::path& out_dir, const ReportFigureOptions& options)
      : out_dir_(out_dir), plot_dir_(out_dir / "report_plots"), options_(options) {
    fs::create_directories(plot_dir_);
  }

  void Data(const std::string& name, const std::string& text) {
    WriteText(plot_dir_ / name, text);
  }

  // Writes <id>.gp (header: terminal, output, common style) + body, runs it.
  ReportFigure Draw(const std::string& id, const std::string& title, const std::string& caption,
                    const std::string& body, int height_px = 0) {
    const fs::path png = out_dir_ / ("report_" + id + ".png");
    std::ostringstream gp;
    gp << "# " << title << " (bouncefit report; rerun with: gnuplot " << id << ".gp)\n"
       << "set terminal pngcairo size " << options_.width_px << ","
       << (height_px > 0 ? height_px : options_.height_px)
       << " noenhanced font 'DejaVu Sans,11' linewidth 1.3\n"
       << "set output " << Quote(fs::absolute(png).string()) << "\n"
       << "set datafile missing '?'\n"
       << "set grid lc rgb '#dddddd'\n"
       << "set key top right box opaque\n"
       << "set border lc rgb '#444444'\n"
       << body << "unset output\n";
    const fs::path script = plot_dir_ / (id + ".gp");
    WriteText(script, gp.str());
    RunGnuplot(script, options_.gnuplot);
    if (!fs::exists(png) || fs::file_size(png) == 0) {
      throw std::runtime_error("gnuplot wrote no image for " + script.string());
    }
    return {id, title, caption, png};
  }

 private:
  fs::path out_dir_, plot_dir_;
  ReportFigureOptions options_;
};

// The time axis: real seconds (a slow-motion file's stamps times its time scale).
std::string TimeAxis(const ReportRunData& run) {
  return run.time_scale == 1 ? "set xlabel 'time since first frame (s)'\n"
                             : "set xlabel 'real time since first frame (s)'\n";
}
std::string RealTimeNote(const ReportRunData& run) {
  if (run.time_scale == 1) return "";
  return fmt::format(" Times in real seconds: the file plays {:.2f}x slower than real time (its stamps x {:.4f}).",
                     1 / run.time_scale, run.time_scale);
}

bool HasFoundRows(const ReportRunData& run) {
  return std::any_of(run.track.begin(), run.track.end(), [](const auto& r) {
    return r.found && std::isfinite(r.cy_px) && std::isfinite(r.h_px);
  });
}

// "t height" per frame, a blank line wherever the ball was lost (a gap in the curve).
std::string HeightSeries(const ReportRunData& run, bool metres, double reference_px) {
  std::ostringstream s;
  s << "# t_s " << (metres ? "height_m" : "height_px") << "\n";
  bool in_gap = false;
  for (const auto& r : run.track) {
    double h = kReportNaN;
    if (r.found) {
      if (metres) {
        h = BallBottomHeightM(r, *run.calibration);
      } else if (std::isfinite(r.cy_px) && std::isfinite(r.h_px)) {
        h = reference_px - (r.cy_px + 0.5 * r.h_px);
      }
    }
    if (!std::isfinite(h)) {
      if (!in_gap) s << "\n";
      in_gap = true;
      continue;
    }
    in_gap = false;
    s << fmt::format("{:.9g} {:.9g}\n", r.t_s, h);
  }
  return s.str();
}

ReportFigure HeightFigure(const ReportRunData& run, FigureWriter& w) {
  const bool metres = run.calibration && run.calibration->usable();
  double lowest_px = 0;
  if (!metres) {
    for (const auto& r : run.track) {
      if (r.found && std::isfinite(r.cy_px)) lowest_px = std::max(lowest_px, r.cy_px + 0.5 * r.h_px);
    }
  }
  w.Data("height.dat", HeightSeries(run, metres, lowest_px));
  std::ostringstream apex;
  apex << "# t_s height label\n";
  int apexes = 0;
  for (const auto& p : run.peaks) {
    const double h = metres ? p.height_m : kReportNaN;
    if (!std::isfinite(h)) continue;
    apex << fmt::format("{:.9g} {:.9g} \"{}: {:.3f} m\"\n", p.t_s, h, p.bounce, h);
    ++apexes;
  }
  w.Data("apexes.dat", apex.str());
  // With sound: a strip under the height plot, on the same time axis, with the waveform
  // and the impacts (heard: red, seen only: green).
  const bool strip = !run.waveform.empty() || !run.impacts.empty();
  std::ostringstream gp;
  if (strip) {
    double t0 = 1e300, t1 = -1e300;
    for (const auto& r : run.track) t0 = std::min(t0, r.t_s), t1 = std::max(t1, r.t_s);
    gp << "set multiplot\n"
       << "set lmargin at screen 0.09\nset rmargin at screen 0.97\n"
       << "set tmargin at screen 0.93\nset bmargin at screen 0.42\n";
    if (t1 > t0) gp << fmt::format("set xrange [{:.9g}:{:.9g}]\n", t0, t1);
  }
  gp << "set title 'Tracked height over time with detected apexes'\n"
     << (strip ? "set format x ''\n" : TimeAxis(run))
     << (metres ? "set ylabel 'ball bottom above floor (m)'\n"
                : "set ylabel 'ball bottom above lowest tracked point (px)'\n")
     << "set yrange [0:*]\n"
     << "plot 'height.dat' using 1:2 with lines lw 1.5 lc rgb '#1f77b4' title 'tracked height'";
  if (apexes > 0) {
    gp << ", \\\n  'apexes.dat' using 1:2 with points pt 7 ps 1.4 lc rgb '#d62728' "
          "title 'detected apex', \\\n"
       << "  'apexes.dat' using 1:2:3 with labels offset 0,1.1 font ',9' notitle";
  }
  gp << "\n";
  if (strip) {
    double top = 0;
    std::ostringstream wave, heard, seen;
    wave << "# t_s peak\n";
    for (const auto& s : run.waveform) {
      wave << fmt::format("{:.9g} {:.9g}\n", s.t_s, s.peak);
      top = std::max(top, s.peak);
    }
    if (!(top > 0)) top = 1;
    for (const auto& i : run.impacts)
      (i.source == "video" ? seen : heard) << fmt::format("{:.9g} 0 0 {:.9g}\n", i.t_s, 1.05 * top);
    w.Data("waveform.dat", wave.str());
    w.Data("impacts_heard.dat", "# t_s 0 0 dy\n" + heard.str());
    w.Data("impacts_seen.dat", "# t_s 0 0 dy\n" + seen.str());
    gp << "set tmargin at screen 0.38\nset bmargin at screen 0.18\n"
       << "unset title\nset format x '%g'\n" << TimeAxis(run)
       << fmt::format("set ylabel 'sound'\nset yrange [0:{:.9g}]\n", 1.1 * top)
       << fmt::format("set ytics {:.9g}\nset format y '%.2f'\n", top / 2)
       << "set key at screen 0.97, screen 0.0 right bottom horizontal nobox\n"
       << "plot 'waveform.dat' using 1:2 with filledcurves y1=0 lc rgb '#999999' "
          "title 'sound (peak per 5 ms)'";
    if (!heard.str().empty())
      gp << ", \\\n  'impacts_heard.dat' using 1:2:3:4 with vectors nohead lw 1.5 lc rgb '#d62728' "
            "title 'impact heard'";
    if (!seen.str().empty())
      gp << ", \\\n  'impacts_seen.dat' using 1:2:3:4 with vectors nohead dt 2 lw 1.5 lc rgb '#2ca02c' "
            "title 'impact seen only'";
    gp << "\nunset multiplot\n";
  }
  return w.Draw("height", "Tracked height and detected apexes",
                std::string(metres ? "Ball bottom above the floor (m) from track.csv and calibration.json "
                         "against time since the first frame (s); red: apexes of peaks.csv "
                         "(bounce index: height in m). The paper's Fig. 6."
                       : "No calibration: ball bottom in pixels above the lowest tracked point "
                         "against time (s).") +
                    (strip ? " Below: the sound track's peak amplitude per 5 ms (waveform.csv) "
                             "with the impacts of impacts.csv, heard (red) or seen only (green, dashed)."
                           : ""),
                gp.str());
}

ReportFigure TrajectoryFigure(const ReportRunData& run, FigureWriter& w, bool have_recorded) {
  std::ostringstream sim;
  sim << "# t_s height_m (a blank line between drops)\n";
  for (size_t i = 0; i < run.simulated.size(); ++i) {
    const auto& s = run.simulated[i];
    if (i > 0 && s.drop != run.simulated[i - 1].drop) sim << "\n";
    sim << fmt::format("{:.9g} {:.9g}\n", s.t_s, s.height_m);
  }
  w.Data("simulated.dat", sim.str());
  std::ostringstream gp;
  gp << "set title 'Recorded vs simulated trajectory'\n"
     << TimeAxis(run)
     << "set ylabel 'ball bottom above floor (m)'\n"
     << "set yrange [0:*]\nplot ";
  if (have_recorded) {
    gp << "'height.dat' using 1:2 with lines lw 2 lc rgb '#1f77b4' title 'recorded (tracked)', ";
  }
  gp << "'simulated.dat' using 1:2 with lines lw 1.5 dt 2 lc rgb '#ff7f0e' "
        "title 'simulated (final coefficients)'\n";
  return w.Draw("trajectory", "Recorded vs simulated trajectory",
                "Ball bottom above the floor (m) against time (s): the tracked ball and the "
                "model with the final coefficients (simulated.csv), each drop's simulated ball "
                "released at the apex its fit started from. The paper's Fig. 7." + RealTimeNote(run),
                gp.str());
}

ReportFigure BouncesFigure(const ReportRunData& run, FigureWriter& w) {
  // Paired by drop and bounce number, as the fit took them (coefficients.json's drops).
  const std::map<std::pair<int, int>, ReportFitPair> fitted = FinalFitByBounce(run);
  bool several = false;
  for (const auto& p : run.peaks) several = several || p.drop != run.peaks.front().drop;
  std::ostringstream rec, sim, diff;
  rec << "# position height_m sigma_m label\n";
  sim << "# position simulated_m\n";
  diff << "# position simulated_minus_recorded_mm sigma_mm drop bounce label\n";
  int position = -1, compared = 0;
  for (size_t i = 0; i < run.peaks.size(); ++i) {
    const ReportPeak& p = run.peaks[i];
    // The heights the final fit took (refitted, or heard), against what it simulated.
    const double h = p.HeightToUse();
    if (!std::isfinite(h)) continue;
    // One position per row; a new drop leaves a gap.
    position += (i > 0 && p.drop != run.peaks[i - 1].drop) ? 2 : 1;
    double sigma = p.height_sigma_m;
    if (!std::isfinite(sigma) && run.calibration) sigma = ApexHeightSigmaM(h, *run.calibration);
    if (!std::isfinite(sigma)) sigma = 0;
    const std::string label = several ? std::to_string(p.drop) + ":" + std::to_string(p.bounce) : std::to_string(p.bounce);
    rec << fmt::format("{:.9g} {:.9g} {:.9g} \"{}\"\n", position - 0.08, h, sigma, label);
    auto it = fitted.find({p.drop, p.bounce});
    if (it == fitted.end() || !std::isfinite(it->second.simulated_m)) continue;
    sim << fmt::format("{:.9g} {:.9g}\n", position + 0.08, it->second.simulated_m);
    // The difference the fit minimised: against the height it took.
    const double difference_mm = (it->second.simulated_m - it->second.recorded_m) * 1000;
    diff << fmt::format("{} {} {:.9g} {} {} \"{}\"\n", position,
                        std::isfinite(difference_mm) ? fmt::format("{:.9g}", difference_mm) : kMissing, sigma * 1000,
                        p.drop, p.bounce, label);
    ++compared;
  }
  w.Data("bounces_recorded.dat", rec.str());
  w.Data("bounces_difference.dat", diff.str());
  w.Data("bounces_simulated.dat", sim.str());
  const bool compare = compared > 0;
  std::ostringstream gp;
  if (compare) {
    gp << "set multiplot layout 2,1 title 'Bounce heights: recorded vs simulated' font ',13'\n"
       << "set lmargin 12\n";
  } else {
    gp << "set title 'Bounce heights: recorded'\n";
  }
  gp << (several ? "set xlabel 'drop:bounce, as peaks.csv numbers them (0 = release)'\n"
                 : "set xlabel 'bounce, as peaks.csv numbers it (0 = release)'\n")
     << "set ylabel 'apex height, ball bottom (m)'\n"
     << "set xrange [-0.5:" << position + 0.5 << "]\n"
     << "set yrange [0:*]\n"
     << "plot 'bounces_recorded.dat' using 1:2:3:xtic(4) with yerrorbars pt 7 ps 1.3 lw 1.5 "
        "lc rgb '#1f77b4' title 'recorded (±1 sigma)'";
  if (compare) {
    gp << ", \\\n  'bounces_simulated.dat' using 1:2 with points pt 5 ps 1.3 lc rgb '#ff7f0e' "
          "title 'simulated (final fit)'\n"
       << "set ylabel 'simulated - recorded (mm)'\nset yrange [*:*]\n"
       << "plot 'bounces_difference.dat' using 1:2:3:xtic(6) with yerrorbars pt 5 ps 1.2 lw 1.5 "
          "lc rgb '#ff7f0e' title 'simulated - recorded, bars: ±1 sigma of the recorded height', "
          "0 with lines dt 2 lc rgb '#888888' notitle\n"
       << "unset multiplot";
  }
  gp << "\n";
  return w.Draw("bounces", "Bounce heights, recorded vs simulated",
                "Top: apex height of each bounce (m), recorded (peaks.csv) with error bars of "
                "one standard uncertainty, and simulated by the final fit, each simulated apex "
                "beside the bounce of the same number (coefficients.json's drops: the fit's "
                "simulated ball starts at its start apex). Bottom: simulated minus the recorded "
                "height the fit took (mm), against the recorded uncertainty.",
                gp.str(), compare ? 640 : 0);
}

ReportFigure CoefficientsFigure(const ReportRunData& run, FigureWriter& w) {
  // Coefficient order of first appearance; one data file per coefficient with two blocks
  // (index 0: updates after each bounce, index 1: final fits).
  std::vector<std::string> names;
  std::map<std::string, std::string> updates, finals;
  std::map<std::string, bool> identifiable;
  std::ostringstream residual;
  residual << "# after_bounce residual_mm final\n";
  // One model's history: the final fit's (a run may also fit a quick model on the way).
  const ReportFit* last = run.FinalFit();
  const std::string model = last ? last->model : std::string();
  for (const auto& f : run.fits) {
    if (f.model != model) continue;
    for (const auto& c : f.coefficients) {
      if (!identifiable.count(c.name)) {
        names.push_back(c.name);
        identifiable[c.name] = c.identifiable;
      } else {
        identifiable[c.name] = identifiable[c.name] || c.identifiable;
      }
      auto& block = f.final ? finals[c.name] : updates[c.name];
      block += fmt::format("{} {} {:.9g}\n", f.after_bounce,
                           std::isfinite(c.value) ? fmt::format("{:.9g}", c.value) : kMissing,
                           std::isfinite(c.sigma) ? c.sigma : 0);
    }
    residual << fmt::format("{} {} {}\n", f.after_bounce,
                            std::isfinite(f.residual_m) ? fmt::format("{:.9g}", f.residual_m * 1000) : kMissing,
                            f.final ? 1 : 0);
  }
  w.Data("residual.dat", residual.str());
  const int panels = static_cast<int>(names.size()) + 1;
  const int cols = panels >= 3 ? 3 : panels;
  const int rows = (panels + cols - 1) / cols;
  std::ostringstream gp;
  gp << "set multiplot layout " << rows << "," << cols
     << " title " << Quote("Coefficient history per bounce: " + model + " model") << " font ',13'\n"
     << "set key off\nset xlabel 'after bounce'\nset xtics 1\nset offsets 0.3,0.3,0,0\n";
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string file = "coefficient_" + std::to_string(i) + ".dat";
    w.Data(file, "# after_bounce value sigma\n" +
                     (updates[names[i]].empty() ? std::string("?  ?  ?\n") : updates[names[i]]) +
                     "\n\n" +
                     (finals[names[i]].empty() ? std::string("?  ?  ?\n") : finals[names[i]]));
    gp << "set title " << Quote(names[i] + (identifiable[names[i]] ? "" : " (not identifiable)"))
       << "\nset ylabel 'value'\n"
       << "plot " << Quote(file) << " index 0 using 1:2:3 with yerrorlines pt 7 lc rgb '#1f77b4'";
    if (!finals[names[i]].empty()) {
      gp << ", " << Quote(file) << " index 1 using 1:2:3 with yerrorbars pt 9 ps 1.6 "
                                   "lc rgb '#d62728'";
    }
    gp << "\n";
  }
  gp << "set title 'RMS residual of bounce heights'\nset ylabel 'residual (mm)'\nset yrange [0:*]\n"
     << "plot 'residual.dat' using 1:($3==0?$2:1/0) with linespoints pt 7 lc rgb '#2ca02c', "
        "'residual.dat' using 1:($3==1?$2:1/0) with points pt 9 ps 1.6 lc rgb '#d62728'\n"
     << "unset multiplot\n";
  return w.Draw("coefficients", "Coefficient history per bounce",
                "Each coefficient of the final fit's model (" + model + "; units as in the "
                "table below) after each bounce's fit, with "
                "its standard uncertainty as error bar where known; red triangles: the final "
                "fit. Last panel: RMS of simulated minus recorded bounce heights (mm).",
                gp.str(), std::max(320, 300 * rows));
}

ReportFigure AspectFigure(const ReportRunData& run, FigureWriter& w) {
  std::ostringstream s;
  s << "# t_s width_over_height\n";
  bool in_gap = false;
  for (const auto& r : run.track) {
    if (!r.found || !(r.h_px > 0) || !std::isfinite(r.w_px)) {
      if (!in_gap) s << "\n";
      in_gap = true;
      continue;
    }
    in_gap = false;
    s << fmt::format("{:.9g} {:.9g}\n", r.t_s, r.w_px / r.h_px);
  }
  w.Data("aspect.dat", s.str());
  std::ostringstream gp;
  gp << "set title 'Width/height ratio of the ball box'\n"
     << TimeAxis(run)
     << "set ylabel 'box width / box height (-)'\n"
     << "plot 'aspect.dat' using 1:2 with lines lc rgb '#9467bd' title 'w/h', "
        "1 with lines dt 2 lc rgb '#888888' title 'round'\n";
  return w.Draw("aspect", "Width/height ratio over time",
                "Box width divided by box height (dimensionless) against time (s): values "
                "above 1 at impacts show the ball squashing against the floor.",
                gp.str(), 360);
}

}  // namespace

std::vector<ReportFigure> WriteReportFigures(const ReportRunData& run, const fs::path& out_dir,
                                             const ReportFigureOptions& options,
                                             std::vector<std::string>* skipped) {
  std::vector<std::string> local_skipped;
  if (!skipped) skipped = &local_skipped;
  if (FindGnuplot(options.gnuplot).empty()) {
    throw std::runtime_error("gnuplot not found ('" + options.gnuplot.executable +
                             "'); install the Debian package gnuplot-nox");
  }
  FigureWriter w(out_dir, options);
  std::vector<ReportFigure> figures;
  const bool found = HasFoundRows(run);
  const bool metres = run.calibration && run.calibration->usable();
  if (found) {
    figures.push_back(HeightFigure(run, w));
  } else {
    skipped->push_back("height: track.csv has no frame with the ball found");
  }
  if (!run.simulated.empty()) {
    figures.push_back(TrajectoryFigure(run, w, found && metres));
  } else {
    skipped->push_back("trajectory: simulated.csv absent (no final fit yet)");
  }
  if (std::any_of(run.peaks.begin(), run.peaks.end(),
                  [](const auto& p) { return std::isfinite(p.height_m); })) {
    figures.push_back(BouncesFigure(run, w));
  } else {
    skipped->push_back("bounces: no peak with a height in metres in peaks.csv");
  }
  if (std::any_of(run.fits.begin(), run.fits.end(),
                  [](const auto& f) { return !f.coefficients.empty(); })) {
    figures.push_back(CoefficientsFigure(run, w));
  } else {
    skipped->push_back("coefficients: no fit update in fit.jsonl yet");
  }
  if (found) {
    figures.push_back(AspectFigure(run, w));
  } else {
    skipped->push_back("aspect: track.csv has no frame with the ball found");
  }
  return figures;
}

}  // namespace bouncefit
