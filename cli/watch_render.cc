#include "cli/watch_render.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit::cli {
namespace {

// A number the watch does not know yet (NaN: no stream start, no flight time) shows as "-".
constexpr const char* kUnknown = "-";

std::string Pad(std::string s, size_t width) {
  if (s.size() > width) s.resize(width);
  s.append(width - s.size(), ' ');
  return s;
}

std::string Rule(int cols, const std::string& title, bool unicode) {
  const std::string dash = unicode ? "\u2500" : "-";
  std::string out = dash + dash + " " + title + " ";
  const int used = static_cast<int>(title.size()) + 4;
  for (int i = used; i < cols; ++i) out += dash;
  return out;
}

double StreamSeconds(const WatchState& s, int64_t utime) {
  if (!s.has_stream_start()) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(utime - s.stream_start_utime()) * 1e-6;
}

// Max height per time bucket over the trace window ending at the last box.
std::vector<double> Buckets(const WatchState& state, int width, double window_s, bool* metres) {
  std::vector<double> b(std::max(width, 1), std::numeric_limits<double>::quiet_NaN());
  *metres = false;
  const auto& trace = state.trace();
  if (trace.empty()) {
    state.SampleHeight({0, false, 0, 0, 0}, metres);
    return b;
  }
  const int64_t end = trace.back().utime;
  const double span = window_s * 1e6;
  for (const auto& s : trace) {
    const double h = state.SampleHeight(s, metres);
    if (!std::isfinite(h)) continue;
    const double age = static_cast<double>(end - s.utime);
    int i = width - 1 - static_cast<int>(age / span * width);
    if (i < 0 || i >= width) continue;
    if (!std::isfinite(b[i]) || h > b[i]) b[i] = h;
  }
  return b;
}

// The chart spans the trace received so far, from 2 s up to the full trace window.
double ChartWindowS(const WatchState& state) {
  const auto& trace = state.trace();
  if (trace.size() < 2) return 2;
  const double span = static_cast<double>(trace.back().utime - trace.front().utime) * 1e-6;
  return std::clamp(span, 2.0, 10.0);
}

// One row under the height chart, its columns the chart's: '*' where an impact was heard
// (alone or also seen), '^' where it was only seen.
std::string ImpactRow(const WatchState& state, int width, double window_s) {
  std::string row(std::max(width, 1), ' ');
  const auto& trace = state.trace();
  if (trace.empty()) return row;
  const int64_t end = trace.back().utime;
  const double span = window_s * 1e6;
  for (const auto& m : state.impacts()) {
    const double age = static_cast<double>(end - m.utime);
    const int i = width - 1 - static_cast<int>(std::floor(age / span * width));
    if (i < 0 || i >= width) continue;
    if (m.source != "video" || row[i] == ' ') row[i] = m.source == "video" ? '^' : '*';
  }
  return row;
}

// "impacts  7: 5 heard (3 also seen), 2 seen only; last at t=4.321 s, heard"
std::string ImpactSummary(const WatchState& s) {
  int heard = 0, both = 0, seen = 0;
  for (const auto& m : s.impacts()) {
    heard += m.source != "video";
    both += m.source == "both";
    seen += m.source == "video";
  }
  std::string line = fmt::format("impacts  {}: {} heard ({} also seen), {} seen only", s.impacts().size(), heard, both,
                                 seen);
  if (!s.impacts().empty()) {
    const impact_t& last = s.impacts().back();
    const double t = StreamSeconds(s, last.utime);
    line += fmt::format("; last at t={} s, {}", std::isfinite(t) ? fmt::format("{:.3f}", t) : kUnknown,
                        last.source == "video" ? "seen" : "heard");
  }
  return line;
}

// The latest fit's simulated apex for a peak's row, paired by bounce number: the ball starts
// at the fit's start apex ("start") and its k-th rebound is bounce start + k; blank where the
// fit is of another drop or did not reach the bounce.
std::string SimulatedApexText(const WatchState& s, const bounce_peak_t& p) {
  if (!s.fit() || s.fit()->sequence != p.sequence) return "";
  const fit_update_t& f = *s.fit();
  if (p.bounce == f.start_bounce) return "start";
  const int i = p.bounce - f.start_bounce - 1;
  if (i < 0 || p.bounce > f.after_bounce || i >= static_cast<int>(f.simulated_m.size())) return "";
  return fmt::format("{:.4f}", f.simulated_m[static_cast<size_t>(i)]);
}

}  // namespace

std::string Sparkline(const WatchState& state, int width, bool unicode) {
  bool metres = false;
  const auto b = Buckets(state, width, ChartWindowS(state), &metres);
  double top = 0;
  for (double v : b) if (std::isfinite(v)) top = std::max(top, v);
  static const char* kBlocks[] = {"\u2581", "\u2582", "\u2583", "\u2584",
                                  "\u2585", "\u2586", "\u2587", "\u2588"};
  static const char kAscii[] = "_.-:=+*#";
  std::string out;
  for (double v : b) {
    if (!std::isfinite(v) || top <= 0) {
      out += ' ';
      continue;
    }
    const int level = std::clamp(static_cast<int>(std::lround(std::max(v, 0.0) / top * 7)), 0, 7);
    if (unicode) out += kBlocks[level];
    else out += kAscii[level];
  }
  return out;
}

std::string WatchCalibrationLine(const calibration_t& c) {
  return fmt::format("calibration  {:.2f} +- {:.2f} px/m  roll {:.2f} +- {:.2f} deg  floor {:.1f} +- {:.1f} px  ({}, {} "
                     "frames)",
                     c.px_per_m, c.px_per_m_sigma, c.roll_rad * 180 / M_PI, c.roll_sigma_rad * 180 / M_PI, c.floor_px,
                     c.floor_sigma_px, c.method, c.samples);
}

std::string WatchPeakLine(const WatchState& s, const bounce_peak_t& m) {
  // A row of peaks.csv (the stream ended) shows the height to quote.
  const double h = m.revision == 3 ? m.fused_height_m : m.height_m;
  const double t = StreamSeconds(s, m.apex_utime);
  std::string line = fmt::format("peak  #{:<2}  t={} s  height {} m  +- {} m", m.bounce,
                                 std::isfinite(t) ? fmt::format("{:7.3f}", t) : kUnknown,
                                 std::isfinite(h) ? fmt::format("{:.4f}", h) : kUnknown,
                                 std::isfinite(m.height_sigma_m) ? fmt::format("{:.4f}", m.height_sigma_m) : kUnknown);
  if (std::isfinite(m.flight_height_m)) line += fmt::format("  (flight time: {:.4f} m)", m.flight_height_m);
  if (m.bounce == 0) {
    line += "  release";
  } else {
    for (const auto& p : s.peaks()) {
      const double hp = p.revision == 3 ? p.fused_height_m : p.height_m;
      if (p.bounce == m.bounce - 1 && hp > 0 && h >= 0) {
        line += fmt::format("  e={:.3f}", std::sqrt(h / hp));
      }
    }
  }
  return line;
}

std::string WatchFitLine(const fit_update_t& m) {
  std::string line =
      fmt::format("fit   after #{}{}  {}/{}", m.after_bounce, m.final ? " (final)" : "", m.model, m.method);
  for (int i = 0; i < m.num_coeffs; ++i) line += fmt::format("  {}={:.6g}", m.names[i], m.values[i]);
  line += fmt::format("  residual {:.2f} mm  {} sims  {:.2f} s", m.residual_m * 1e3, m.evaluations, m.wall_time_s);
  return line;
}

std::string WatchImpactLine(const WatchState& s, const impact_t& m) {
  const double t = StreamSeconds(s, m.utime);
  std::string line = fmt::format("impact #{:<2}  t={} s  {}", m.index, std::isfinite(t) ? fmt::format("{:7.3f}", t) : kUnknown,
                                 m.source == "audio"  ? "heard"
                                 : m.source == "both" ? "heard and seen"
                                                      : "seen");
  if (m.source != "video")
    line += fmt::format("  strength {:.4f} (full scale 1)  confidence {:.2f}", m.strength, m.confidence);
  return line;
}

std::string WatchStatusLine(const WatchState& s, int64_t now, const WatchRenderOptions& o) {
  const auto& ch = o.channel_names;
  const char* kinds[] = {"box", "calibration", "peak", "fit", "impact"};
  std::string line;
  for (size_t i = 0; i < 5 && i < ch.size(); ++i) {
    line += fmt::format("{} {:.1f}/s ({})  ", ch[i], s.Rate(kinds[i], now), s.Count(kinds[i]));
  }
  line += fmt::format("| frame gaps {}  ball not found {}  decode failures {}  handler failures {}  restarts {}",
                      s.frame_gaps(), s.lost_frames(), o.decode_failures, o.handler_failures, s.restarts());
  return line;
}

std::vector<std::string> RenderWatch(const WatchState& s, int64_t now,
                                     const WatchRenderOptions& o) {
  const int cols = std::max(o.cols, 60);
  std::vector<std::string> lines;

  // Title and liveness.
  std::string status;
  if (!s.AnyData()) {
    status = "waiting for data (nothing received yet)";
  } else if (s.Waiting(now)) {
    status = fmt::format("waiting for data (no message for {:.1f} s)", s.SilenceS(now));
  } else {
    status = "LIVE";
  }
  std::string title = "bouncefit watch  " + o.source + "  [" + status + "]";
  const double stream_t = StreamSeconds(s, s.last_box_utime());
  if (std::isfinite(stream_t)) title += fmt::format("  stream t={:.2f} s", stream_t);
  lines.push_back(Pad(title, cols));

  // Height trace.
  const int label_w = 9;
  const int chart_w = cols - label_w;
  bool metres = false;
  const double window_s = ChartWindowS(s);
  const auto b = Buckets(s, chart_w, window_s, &metres);
  double top = 0;
  for (double v : b) if (std::isfinite(v)) top = std::max(top, v);
  for (const auto& p : s.peaks()) if (metres && std::isfinite(p.height_m)) top = std::max(top, p.height_m);
  top = top > 0 ? top * 1.05 : 1;
  lines.push_back(Rule(cols,
                       (metres ? "height of the ball bottom above the floor (m), last "
                               : "height (px above the lowest point seen; no calibration yet), last ") +
                           fmt::format("{:.1f} s", window_s),
                       o.unicode));
  static const char* kBlocks[] = {" ", "\u2581", "\u2582", "\u2583", "\u2584",
                                  "\u2585", "\u2586", "\u2587", "\u2588"};
  const int rows = std::max(o.chart_rows, 2);
  for (int r = 0; r < rows; ++r) {
    const int from_bottom = rows - 1 - r;
    std::string label(label_w, ' ');
    if (r == 0) label = Pad(metres ? fmt::format("{:7.3f} ", top) : fmt::format("{:7.0f} ", top), label_w);
    if (r == rows - 1) label = Pad(metres ? "  0.000 " : "      0 ", label_w);
    std::string row = label;
    for (double v : b) {
      if (!std::isfinite(v)) {
        row += ' ';
        continue;
      }
      const double fill = std::clamp(std::max(v, 0.0) / top * rows - from_bottom, 0.0, 1.0);
      const int level = static_cast<int>(std::lround(fill * 8));
      if (o.unicode) {
        row += kBlocks[level];
      } else {
        row += level == 0 ? ' ' : (level < 4 ? '.' : (level < 8 ? ':' : '#'));
      }
    }
    lines.push_back(row);
  }
  lines.push_back(Pad("impacts  ", label_w) + ImpactRow(s, chart_w, window_s));

  // Calibration.
  if (s.calibration()) {
    const auto& c = *s.calibration();
    lines.push_back(Pad(WatchCalibrationLine(c), cols));
  } else {
    lines.push_back(Pad("calibration  not yet known", cols));
  }
  lines.push_back(Pad(ImpactSummary(s) + "   (under the chart: * heard, ^ seen only)", cols));

  // Peaks (left) and coefficients (right), side by side when wide enough.
  std::vector<std::string> left, right;
  left.push_back(fmt::format("peaks, drop {}", std::max(s.current_sequence(), 0)));
  left.push_back(" #    t (s)  height (m)  +- (mm)  flight (m)  e (-)    sim (m)");
  const auto& peaks = s.peaks();
  const size_t max_peaks = 12;
  const size_t first = peaks.size() > max_peaks ? peaks.size() - max_peaks : 0;
  for (size_t i = first; i < peaks.size(); ++i) {
    const auto& p = peaks[i];
    std::string e = p.bounce == 0 ? "release" : "-";
    if (i > 0 && peaks[i - 1].bounce == p.bounce - 1 && peaks[i - 1].height_m > 0 &&
        p.height_m >= 0) {
      e = fmt::format("{:.3f}", std::sqrt(p.height_m / peaks[i - 1].height_m));
    }
    const double t = StreamSeconds(s, p.apex_utime), sigma_mm = p.height_sigma_m * 1e3;
    left.push_back(fmt::format("{:2} {:>8}  {:>10}  {:>6}  {:>10}   {:<7}  {:>7}", p.bounce,
                               std::isfinite(t) ? fmt::format("{:.3f}", t) : kUnknown,
                               std::isfinite(p.height_m) ? fmt::format("{:.4f}", p.height_m) : kUnknown,
                               std::isfinite(sigma_mm) ? fmt::format("{:.2f}", sigma_mm) : kUnknown,
                               std::isfinite(p.flight_height_m) ? fmt::format("{:.4f}", p.flight_height_m) : kUnknown,
                               e, SimulatedApexText(s, p)));
  }
  if (peaks.empty()) left.push_back(" (no apex yet)");

  if (s.fit()) {
    const auto& f = *s.fit();
    right.push_back(
        fmt::format("fit after bounce {}{}  {} / {}", f.after_bounce, f.final ? " (final)" : "", f.model, f.method));
    right.push_back(" coefficient                           value   +- sigma  change");
    const fit_update_t* prev = s.previous_fit();
    for (int i = 0; i < f.num_coeffs; ++i) {
      std::string change = "";
      if (prev) {
        for (int j = 0; j < prev->num_coeffs; ++j) {
          if (prev->names[j] == f.names[i] && prev->values[j] != 0) {
            change = fmt::format("{:+.1f}%", 100 * (f.values[i] / prev->values[j] - 1));
          }
        }
      }
      std::string name = f.names[i];
      if (!f.identifiable[i]) name += " (n/i)";
      right.push_back(fmt::format(" {:<32} {:>11.6g} {:>10}  {}", name, f.values[i],
                                  std::isfinite(f.sigmas[i]) ? fmt::format("{:.3g}", f.sigmas[i]) : kUnknown, change));
    }
    std::string totals =
        fmt::format(" residual {:.2f} mm   {} sims   {:.2f} s", f.residual_m * 1e3, f.evaluations, f.wall_time_s);
    if (f.time_step_s > 0) {
      totals += fmt::format("   step {:.3f} ms x {} iter", f.time_step_s * 1e3, f.iterations);
    }
    right.push_back(totals);
    for (const auto& [model, other] : s.latest_by_model()) {
      if (model == f.model) continue;
      right.push_back(fmt::format(" also {} after #{}{}: residual {:.2f} mm", model, other.after_bounce,
                                  other.final ? " (final)" : "", other.residual_m * 1e3));
    }
    right.push_back(fmt::format(" fit updates received: {}", s.fits_received()));
  } else {
    right.push_back("coefficients");
    right.push_back(" (no fit yet)");
  }

  lines.push_back(Rule(cols, "bounces and coefficients", o.unicode));
  const size_t left_w = 63;
  if (cols >= 110) {
    const size_t n = std::max(left.size(), right.size());
    for (size_t i = 0; i < n; ++i) {
      std::string l = i < left.size() ? left[i] : "";
      std::string r = i < right.size() ? right[i] : "";
      lines.push_back(Pad(Pad(l, left_w) + "| " + r, cols));
    }
  } else {
    for (auto& l : left) lines.push_back(Pad(l, cols));
    for (auto& r : right) lines.push_back(Pad(r, cols));
  }

  // Traffic.
  lines.push_back(Rule(cols, "messages", o.unicode));
  const std::string status_line = WatchStatusLine(s, now, o);
  const size_t bar = status_line.find(" | ");
  if (bar != std::string::npos && status_line.size() > static_cast<size_t>(cols)) {
    lines.push_back(Pad(status_line.substr(0, bar), cols));
    lines.push_back(Pad(" " + status_line.substr(bar + 3), cols));
  } else {
    lines.push_back(Pad(status_line, cols));
  }
  if (o.show_keys) lines.push_back(Pad("q: quit", cols));
  if (o.rows > 0 && static_cast<int>(lines.size()) > o.rows) {
    // Too short a terminal: keep the title, drop chart rows first.
    lines.resize(o.rows);
  }
  return lines;
}

}  // namespace bouncefit::cli
