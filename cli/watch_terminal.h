#pragma once
// The full-screen terminal for `bouncefit watch`: alternate screen, hidden cursor, keys
// read without echo. Everything is restored when the object goes away, and on SIGINT,
// SIGTERM and SIGHUP the loop is told to stop (StopRequested) so that happens.
#include <string>
#include <vector>

namespace bouncefit::cli {

class WatchTerminal {
 public:
  // Takes over stdin/stdout (both must be terminals). Throws std::runtime_error if not.
  WatchTerminal();
  ~WatchTerminal();
  WatchTerminal(const WatchTerminal&) = delete;
  WatchTerminal& operator=(const WatchTerminal&) = delete;

  // Columns and rows of the window now.
  void Size(int* cols, int* rows) const;
  // A key typed since the last call, or 0.
  int ReadKey();
  // Redraws the whole screen with these lines (each at most `cols` columns).
  void Draw(const std::vector<std::string>& lines);

  // Installs the SIGINT/SIGTERM/SIGHUP handlers (also used by plain mode).
  static void InstallStopHandlers();
  static bool StopRequested();

 private:
  bool restored_ = false;
  void Restore();
};

}  // namespace bouncefit::cli
