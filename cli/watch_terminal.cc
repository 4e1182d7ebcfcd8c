#include "cli/watch_terminal.h"

#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <stdexcept>

#include "cli/stop_signal.h"

namespace bouncefit::cli {
namespace {

const std::atomic<bool>* g_stop = nullptr;
termios g_saved{};
bool g_saved_valid = false;

void WriteAll(const std::string& s) {
  size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = ::write(STDOUT_FILENO, s.data() + done, s.size() - done);
    if (n <= 0) return;
    done += static_cast<size_t>(n);
  }
}

}  // namespace

void WatchTerminal::InstallStopHandlers() { g_stop = &StopOnSignal(/*hang_up=*/true); }

bool WatchTerminal::StopRequested() { return g_stop != nullptr && *g_stop; }

WatchTerminal::WatchTerminal() {
  if (!::isatty(STDIN_FILENO) || !::isatty(STDOUT_FILENO)) {
    throw std::runtime_error("the dashboard needs a terminal (use --plain)");
  }
  if (::tcgetattr(STDIN_FILENO, &g_saved) != 0) throw std::runtime_error("cannot read terminal mode");
  g_saved_valid = true;
  termios raw = g_saved;
  raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);  // ISIG kept: Ctrl-C is SIGINT
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  ::tcsetattr(STDIN_FILENO, TCSANOW, &raw);
  InstallStopHandlers();
  // Alternate screen, hidden cursor, cleared.
  WriteAll("\x1b[?1049h\x1b[?25l\x1b[2J\x1b[H");
}

WatchTerminal::~WatchTerminal() { Restore(); }

void WatchTerminal::Restore() {
  if (restored_) return;
  restored_ = true;
  WriteAll("\x1b[0m\x1b[?25h\x1b[?1049l");
  if (g_saved_valid) ::tcsetattr(STDIN_FILENO, TCSANOW, &g_saved);
}

void WatchTerminal::Size(int* cols, int* rows) const {
  winsize ws{};
  if (::ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) {
    *cols = ws.ws_col;
    *rows = ws.ws_row;
  } else {
    *cols = 100;
    *rows = 40;
  }
}

int WatchTerminal::ReadKey() {
  pollfd pfd{STDIN_FILENO, POLLIN, 0};
  if (::poll(&pfd, 1, 0) <= 0 || !(pfd.revents & POLLIN)) return 0;
  unsigned char c = 0;
  if (::read(STDIN_FILENO, &c, 1) != 1) return 0;
  return c;
}

void WatchTerminal::Draw(const std::vector<std::string>& lines) {
  std::string frame = "\x1b[H";
  for (size_t i = 0; i < lines.size(); ++i) {
    frame += lines[i];
    frame += "\x1b[K";
    if (i + 1 < lines.size()) frame += "\r\n";
  }
  frame += "\x1b[J";
  WriteAll(frame);
}

}  // namespace bouncefit::cli
