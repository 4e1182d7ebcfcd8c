#include "cli/run_console.h"

#include <unistd.h>

#include <cmath>
#include <vector>

#include "msgs/msg_json.h"

namespace bouncefit::cli {
namespace {

std::string Format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

}  // namespace

RunConsole::RunConsole(ConsoleMode mode, std::FILE* out)
    : mode_(mode), out_(out), tty_(::isatty(::fileno(out)) != 0) {}

void RunConsole::Line(const std::string& text) {
  if (progress_open_) {
    std::fputs("\r\033[K", out_);
    progress_open_ = false;
  }
  std::fputs(text.c_str(), out_);
  std::fputc('\n', out_);
  // On a terminal the progress line stays at the bottom, under the events.
  if (tty_ && !progress_text_.empty()) {
    std::fputs(progress_text_.c_str(), out_);
    progress_open_ = true;
  }
  std::fflush(out_);
}

void RunConsole::Info(const std::string& line) {
  if (mode_ == ConsoleMode::kHuman) Line(line);
}

void RunConsole::OnCalibration(const calibration_t& m) {
  if (mode_ == ConsoleMode::kJson) {
    auto j = ToJson(m, t0_);
    j["event"] = "calibration";
    Line(j.dump());
  } else if (mode_ == ConsoleMode::kHuman) {
    // The detector refines the scale on every arc: show it again only when it moved.
    const bool moved = last_px_per_m_ <= 0 || m.method != last_method_ ||
                       std::abs(m.px_per_m - last_px_per_m_) > 1e-3 * last_px_per_m_;
    if (!moved) return;
    last_px_per_m_ = m.px_per_m;
    last_method_ = m.method;
    Line(Format("calibration  %.2f +- %.2f px/m (%s, %d frames), roll %.2f deg, floor at %.1f px",
                m.px_per_m, m.px_per_m_sigma, m.method.c_str(), m.samples,
                m.roll_rad * 180 / M_PI, m.floor_px));
  }
}

void RunConsole::OnPeak(const bounce_peak_t& m) {
  heights_[m.bounce] = m.height_m;
  if (mode_ == ConsoleMode::kJson) {
    auto j = ToJson(m, t0_);
    j["event"] = "peak";
    Line(j.dump());
    return;
  }
  if (mode_ != ConsoleMode::kHuman) return;
  std::string line = Format("peak  #%-2d  t=%7.3f s  height %.4f m", m.bounce,
                            SecondsSince(m.apex_utime, t0_), m.height_m);
  if (std::isfinite(m.flight_height_m))
    line += Format("  (flight time: %.4f m)", m.flight_height_m);
  auto prev = heights_.find(m.bounce - 1);
  if (m.bounce == 0) {
    line += "  release";
  } else if (prev != heights_.end() && prev->second > 0) {
    line += Format("  e=%.3f", std::sqrt(m.height_m / prev->second));
  }
  line += Format("  [+%.0f ms]", (m.emitted_utime - m.apex_utime) * 1e-3);
  Line(line);
}

void RunConsole::OnFit(const fit_update_t& m, int64_t published_utime) {
  if (mode_ == ConsoleMode::kJson) {
    auto j = ToJson(m, t0_);
    j["event"] = "fit";
    if (published_utime) j["published_t_s"] = SecondsSince(published_utime, t0_);
    Line(j.dump());
    return;
  }
  if (mode_ != ConsoleMode::kHuman) return;
  std::string line = Format("fit   after #%d%s  %s/%s", m.after_bounce, m.final ? " (final)" : "",
                            m.model.c_str(), m.method.c_str());
  // The few main ones: those the data determines first; the report has them all.
  std::vector<int> order;
  for (int pass = 0; pass < 2; ++pass)
    for (int i = 0; i < m.num_coeffs; ++i)
      if (static_cast<bool>(m.identifiable[i]) == (pass == 0)) order.push_back(i);
  const int shown = std::min(m.num_coeffs, 4);
  for (int k = 0; k < shown; ++k)
    line += Format("  %s=%.4g", m.names[order[k]].c_str(), m.values[order[k]]);
  if (m.num_coeffs > shown) line += Format("  (+%d more)", m.num_coeffs - shown);
  line += Format("  residual %.2f mm  %d evals  %.0f ms", m.residual_m * 1e3, m.evaluations,
                 m.wall_time_s * 1e3);
  Line(line);
}

void RunConsole::Progress(double stream_s, double total_s, int64_t frames, int64_t found) {
  if (mode_ != ConsoleMode::kHuman) return;
  if (last_progress_s_ >= 0 && stream_s - last_progress_s_ < 0.5) return;
  last_progress_s_ = stream_s;
  std::string text = total_s > 0 ? Format("replay %5.1f / %.1f s (%3.0f%%)  %lld frames, ball in %lld",
                                          stream_s, total_s, 100 * stream_s / total_s,
                                          static_cast<long long>(frames),
                                          static_cast<long long>(found))
                                 : Format("capture %5.1f s  %lld frames, ball in %lld", stream_s,
                                          static_cast<long long>(frames),
                                          static_cast<long long>(found));
  ShowProgress(text);
}

void RunConsole::ShowProgress(const std::string& text) {
  if (tty_) {
    progress_text_ = text;
    std::fputs(("\r\033[K" + text).c_str(), out_);
    std::fflush(out_);
    progress_open_ = true;
  } else {
    Line(text);
  }
}

void RunConsole::FitProgress(int simulations, int budget) {
  if (mode_ != ConsoleMode::kHuman) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_fit_progress_ < std::chrono::seconds(1)) return;
  last_fit_progress_ = now;
  ShowProgress(Format("final fit  %d / %d simulations (%3.0f%%)", simulations, budget,
                      budget > 0 ? 100.0 * simulations / budget : 0.0));
}

void RunConsole::Summary(const std::string& human_text, const std::string& json_text) {
  progress_text_.clear();
  if (mode_ == ConsoleMode::kHuman) Line(human_text);
  if (mode_ == ConsoleMode::kJson) Line(json_text);
}

}  // namespace bouncefit::cli
