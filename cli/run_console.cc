#include "cli/run_console.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bouncefit/impact_t.hpp"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"
#include "msgs/msg_json.h"

namespace bouncefit::cli {

RunConsole::RunConsole(ConsoleMode mode, std::FILE* out)
    : mode_(mode), out_(out), tty_(::isatty(::fileno(out)) != 0) {}

RunConsole::~RunConsole() {
  if (!final_rows_.empty()) SayFinalRows();
}

void RunConsole::Follow(LcmBus& bus, const Channels& ch, bool fits) {
  bus.Subscribe<stream_t>(ch.stream, [this](const stream_t& m) { OnStream(m); });
  bus.Subscribe<drop_t>(ch.drop, [this](const drop_t& m) { OnDrop(m); });
  bus.Subscribe<calibration_t>(ch.calibration, [this](const calibration_t& m) { OnCalibration(m); });
  bus.Subscribe<bounce_peak_t>(ch.bounce_peak, [this](const bounce_peak_t& m) { OnPeak(m); });
  if (fits) bus.Subscribe<fit_update_t>(ch.fit_update, [this](const fit_update_t& m) { OnFit(m); });
}

void RunConsole::Line(const std::string& text) {
  if (!final_rows_.empty()) SayFinalRows();
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

void RunConsole::OnStream(const stream_t& m) {
  if (m.state == "start") t0_ = m.utime;
}

void RunConsole::OnCalibration(const calibration_t& m) {
  if (mode_ == ConsoleMode::kJson) {
    auto j = ToJson(m, t0_);
    j["event"] = "calibration";
    Line(j.dump());
  } else if (mode_ == ConsoleMode::kHuman) {
    // The detector refines the scale on every arc: say it again only when it moved by 1%.
    const bool moved = last_px_per_m_ <= 0 || m.method != last_method_ ||
                       std::abs(m.px_per_m - last_px_per_m_) > 1e-2 * last_px_per_m_;
    if (!moved) return;
    last_px_per_m_ = m.px_per_m;
    last_method_ = m.method;
    Line(fmt::format("calibration  {:.2f} +- {:.2f} px/m ({}, {} frames), roll {:.2f} deg, floor at {:.1f} px",
                     m.px_per_m, m.px_per_m_sigma, m.method, m.samples, m.roll_rad * 180 / M_PI, m.floor_px));
  }
}

void RunConsole::OnPeak(const bounce_peak_t& m) {
  const double t = SecondsSince(m.apex_utime, t0_);
  if (m.revision == 3) rows_.emplace_back(m.bounce, m.fused_height_m);
  // e = sqrt(h_k / h_k-1) against the bounce printed before it; above 1 the ball rose higher
  // than it fell from, which no bounce does: one of the two heights is wrong.
  double e = NAN;
  if (m.revision == 0 && m.bounce > 0)
    if (const auto prev = heights_.find({m.sequence, m.bounce - 1}); prev != heights_.end() && prev->second > 0)
      e = std::sqrt(m.height_m / prev->second);
  if (m.revision == 0) heights_[{m.sequence, m.live_bounce}] = m.height_m;
  if (mode_ == ConsoleMode::kJson) {
    auto j = ToJson(m, t0_);
    j["event"] = m.revision == 0 || (m.revision == 3 && m.live_bounce < 0) ? "peak" : "revision";
    if (std::isfinite(e)) j["e"] = e;
    if (e > 1) j["suspect"] = "higher than the apex before";
    Line(j.dump());
    return;
  }
  if (mode_ != ConsoleMode::kHuman) return;
  if (m.revision == 3) {
    final_rows_.push_back(m);
    return;
  }
  if (m.revision == 0) {
    // A bounce, printed once, as it is emitted (heard only: with the final rows).
    std::string line = fmt::format("peak  #{:<2d}  t={:7.3f} s  height {:.4f} m", m.bounce, t, m.height_m);
    if (m.bounce == 0)
      line += "  release";
    else if (std::isfinite(e))
      line += fmt::format("  e={:.3f}{}", e, e > 1 ? " (higher than the apex before: suspect)" : "");
    line += fmt::format("  [+{:.0f} ms]", (m.emitted_utime - m.apex_utime) * 1e-3);
    ++peak_lines_;
    Line(line);
  } else if (m.revision == 1) {
    Line(fmt::format("  revised #{}: heard end to end, flight-time height {:.4f} m", m.live_bounce, m.height_m));
  } else if (m.revision == 4) {
    Line(fmt::format("  revised #{}: withdrawn (the sound heard one arc where the picture saw two)", m.live_bounce));
  }
  // Revision 2 (the drop's refit) is said in one line by the detect node when the drop ends.
}

void RunConsole::OnDrop(const drop_t& m) {
  if (m.state == "done" && !final_rows_.empty()) SayFinalRows();
}

void RunConsole::SayFinalRows() {
  const std::vector<bounce_peak_t> rows = std::move(final_rows_);
  final_rows_.clear();
  std::vector<std::string> lines;
  // Rows printed live, in their live order, each with its shift; a run of rows (one drop, live
  // numbers in a row) shifted alike is one line, a row alone its own.
  std::vector<const bounce_peak_t*> seen;
  for (const auto& m : rows)
    if (m.live_bounce >= 0) seen.push_back(&m);
  std::stable_sort(seen.begin(), seen.end(), [](const bounce_peak_t* a, const bounce_peak_t* b) {
    return std::make_pair(a->sequence, a->live_bounce) < std::make_pair(b->sequence, b->live_bounce);
  });
  // Why a drop's rows moved up: bounces heard before the first one the picture saw.
  const auto heard_first = [&](int sequence) {
    int64_t first_seen = INT64_MAX;
    for (const bounce_peak_t* m : seen)
      if (m->sequence == sequence) first_seen = std::min(first_seen, m->apex_utime);
    return std::count_if(rows.begin(), rows.end(), [&](const bounce_peak_t& h) {
      return h.live_bounce < 0 && h.sequence == sequence && h.apex_utime < first_seen;
    });
  };
  for (size_t i = 0; i < seen.size();) {
    const bounce_peak_t& a = *seen[i];
    const int shift = a.bounce - a.live_bounce;
    size_t j = i + 1;
    while (j < seen.size() && seen[j]->sequence == a.sequence &&
           seen[j]->live_bounce == seen[j - 1]->live_bounce + 1 && seen[j]->bounce - seen[j]->live_bounce == shift)
      ++j;
    const bounce_peak_t& b = *seen[j - 1];
    if (shift != 0 && j - i == 1) {
      lines.push_back(fmt::format("  revised #{}: is bounce {} (the impacts heard number it)", a.live_bounce, a.bounce));
    } else if (shift != 0) {
      const auto heard = heard_first(a.sequence);
      const std::string why = shift > 0 && heard == shift
                                  ? heard == 1 ? "a bounce heard before the first one seen"
                                               : fmt::format("{} bounces heard before the first one seen", heard)
                                  : "the impacts heard number them";
      lines.push_back(fmt::format("renumbered: #{}-#{} are #{}-#{} ({})", a.live_bounce, b.live_bounce, a.bounce,
                                  b.bounce, why));
    }
    i = j;
  }
  for (const auto& m : rows)
    if (m.live_bounce < 0) {
      ++peak_lines_;
      lines.push_back(fmt::format("peak  #{:<2d}  t={:7.3f} s  height {:.4f} m  heard only (flight time)", m.bounce,
                                  SecondsSince(m.apex_utime, t0_), m.fused_height_m));
    }
  for (const std::string& line : lines) Line(line);
}

void RunConsole::OnFit(const fit_update_t& m) {
  if (mode_ == ConsoleMode::kJson) {
    auto j = ToJson(m, t0_);
    j["event"] = "fit";
    Line(j.dump());
    return;
  }
  if (mode_ != ConsoleMode::kHuman) return;
  std::string line = fmt::format("fit   after #{}{}  {}/{}", m.after_bounce, m.final ? " (final)" : "", m.model, m.method);
  // The few main ones: those the data determines first; the report has them all.
  std::vector<int> order;
  for (int pass = 0; pass < 2; ++pass)
    for (int i = 0; i < m.num_coeffs; ++i)
      if (static_cast<bool>(m.identifiable[i]) == (pass == 0)) order.push_back(i);
  const int shown = std::min(m.num_coeffs, 4);
  for (int k = 0; k < shown; ++k) line += fmt::format("  {}={:.4g}", m.names[order[k]], m.values[order[k]]);
  if (m.num_coeffs > shown) line += fmt::format("  (+{} more)", m.num_coeffs - shown);
  line += fmt::format("  residual {:.2f} mm  {} evals  {:.0f} ms", m.residual_m * 1e3, m.evaluations, m.wall_time_s * 1e3);
  Line(line);
}

void RunConsole::Progress(double stream_s, double total_s, int64_t frames, int64_t found) {
  if (mode_ != ConsoleMode::kHuman) return;
  if (last_progress_s_ >= 0 && stream_s - last_progress_s_ < 0.5) return;
  last_progress_s_ = stream_s;
  ShowProgress(total_s > 0 ? fmt::format("replay {:5.1f} / {:.1f} s ({:3.0f}%)  {} frames, ball in {}", stream_s,
                                         total_s, 100 * stream_s / total_s, frames, found)
                           : fmt::format("capture {:5.1f} s  {} frames, ball in {}", stream_s, frames, found));
}

void RunConsole::ShowProgress(const std::string& text) {
  if (tty_) {
    if (!final_rows_.empty()) SayFinalRows();
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
  ShowProgress(fmt::format("final fit  {} / {} simulations ({:3.0f}%)", simulations, budget,
                           budget > 0 ? 100.0 * simulations / budget : 0.0));
}

void RunConsole::Summary(const std::string& human_text, const std::string& json_text) {
  progress_text_.clear();
  if (mode_ == ConsoleMode::kHuman) Line(human_text);
  if (mode_ == ConsoleMode::kJson) Line(json_text);
}

}  // namespace bouncefit::cli
