#pragma once
// What `run` prints while it works, from the messages on the bus: the clock and scale when
// they change, each bounce once when it is emitted and later revisions of it as revisions,
// each fit, the nodes' notices; one JSON object per line with --json. A progress line while
// replaying a file, and a short summary at the end. A rebound higher than the apex before it
// is said to be suspect; when the stream's final rows renumber the bounces already printed,
// one line says each run of rows moved by the same shift.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/drop_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "bouncefit/stream_t.hpp"

namespace bouncefit {
class LcmBus;
struct Channels;
}

namespace bouncefit::cli {

enum class ConsoleMode { kHuman, kJson, kQuiet };

class RunConsole {
 public:
  RunConsole(ConsoleMode mode, std::FILE* out);
  ~RunConsole();  // says the final rows still held (no DROP "done" came)

  // Prints what goes by on `bus` (the session's own): the stream, calibrations, bounces and,
  // with fits, the fit updates.
  void Follow(LcmBus& bus, const Channels& channels, bool fits = true);

  void Info(const std::string& line);  // human mode only
  void OnStream(const stream_t& m);
  void OnCalibration(const calibration_t& m);
  void OnPeak(const bounce_peak_t& m);
  void OnFit(const fit_update_t& m);
  // "done": the final rows have all gone out (the renumbering is said then).
  void OnDrop(const drop_t& m);
  // Stream position and total (total <= 0 when unknown). Rate-limited to ~2 lines/s of
  // stream time; redrawn in place on a terminal.
  void Progress(double stream_s, double total_s, int64_t frames, int64_t found);
  // The final fit's progress, at most once a second (wall clock).
  void FitProgress(int simulations, int budget);
  void Summary(const std::string& human_text, const std::string& json_text);

  int peak_lines() const { return peak_lines_; }
  // The rows of peaks.csv as they went out once the stream ended (bounce, height to quote, m).
  const std::vector<std::pair<int, double>>& rows() const { return rows_; }

 private:
  void Line(const std::string& text);  // ends an in-place progress line first
  // The final rows (revision 3) come as a burst: held until it ends, then the renumbering in
  // one line per run of rows shifted alike, and the bounces heard only.
  void SayFinalRows();
  void ShowProgress(const std::string& text);  // in place on a terminal, else a line
  ConsoleMode mode_;
  std::FILE* out_;
  bool tty_;
  bool progress_open_ = false;
  std::chrono::steady_clock::time_point last_fit_progress_{};
  std::string progress_text_;  // redrawn under each event line on a terminal
  double last_progress_s_ = -1;
  int64_t t0_ = 0;
  double last_px_per_m_ = 0;  // last calibration shown
  std::string last_method_;
  std::map<std::pair<int, int>, double> heights_;  // (sequence, bounce) -> height shown
  std::vector<bounce_peak_t> final_rows_;  // held by SayFinalRows
  int peak_lines_ = 0;
  std::vector<std::pair<int, double>> rows_;
};

}  // namespace bouncefit::cli
