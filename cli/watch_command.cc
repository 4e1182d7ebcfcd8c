// bouncefit watch: attach to a running session over LCM and show it live: a full-screen
// dashboard on a terminal, event lines with --plain (or when stdout is not a terminal), one
// snapshot with --once.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "cli/bus_flags.h"
#include "cli/commands.h"
#include "cli/number_checks.h"
#include "cli/watch_render.h"
#include "cli/watch_state.h"
#include "cli/watch_terminal.h"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"

namespace bouncefit::cli {
namespace {

struct WatchFlags {
  std::string lcm_url = kDefaultLcmUrl;
  Channels channels;
  bool plain = false;
  bool once = false;
  bool ascii = false;
  double duration_s = 0;       // 0: until q / Ctrl-C
  double refresh_hz = 10;
  double status_every_s = 5;   // plain mode
  WatchConfig config;
};

int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool UnicodeLocale() {
  for (const char* var : {"LC_ALL", "LC_CTYPE", "LANG"}) {
    const char* v = std::getenv(var);
    if (v && *v) {
      const std::string s = v;
      return s.find("UTF-8") != std::string::npos || s.find("utf8") != std::string::npos ||
             s.find("UTF8") != std::string::npos || s.find("utf-8") != std::string::npos;
    }
  }
  return false;
}

void RunWatch(const WatchFlags& f) {
  LcmBus bus(f.lcm_url);
  WatchState state(f.config);
  const bool tty = ::isatty(STDOUT_FILENO) && ::isatty(STDIN_FILENO);
  const bool dashboard = tty && !f.plain && !f.once;
  const bool plain = !dashboard && !f.once;
  auto say = [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  int64_t restarts_seen = 0;
  bus.Subscribe<ball_box_t>(f.channels.ball_box, [&](const ball_box_t& m) {
    state.OnBox(m, NowUtime());
    if (state.restarts() != restarts_seen) {
      restarts_seen = state.restarts();
      if (plain) say("watch: the producer restarted: a new stream");
    }
  });
  bus.Subscribe<stream_t>(f.channels.stream, [&](const stream_t& m) { state.OnStream(m, NowUtime()); });
  bus.Subscribe<calibration_t>(f.channels.calibration, [&](const calibration_t& m) {
    state.OnCalibration(m, NowUtime());
    if (plain) say(WatchCalibrationLine(m));
  });
  bus.Subscribe<bounce_peak_t>(f.channels.bounce_peak, [&](const bounce_peak_t& m) {
    state.OnPeak(m, NowUtime());
    if (plain) say(WatchPeakLine(state, m));
  });
  bus.Subscribe<fit_update_t>(f.channels.fit_update, [&](const fit_update_t& m) {
    state.OnFit(m, NowUtime());
    if (plain) say(WatchFitLine(m));
  });
  bus.Subscribe<impact_t>(f.channels.impact, [&](const impact_t& m) {
    state.OnImpact(m, NowUtime());
    if (plain) say(WatchImpactLine(state, m));
  });

  WatchRenderOptions render;
  render.unicode = !f.ascii && UnicodeLocale();
  render.source = f.lcm_url;
  render.channel_names = {f.channels.ball_box, f.channels.calibration, f.channels.bounce_peak,
                          f.channels.fit_update, f.channels.impact};

  std::unique_ptr<WatchTerminal> terminal;
  if (dashboard) terminal = std::make_unique<WatchTerminal>();
  else WatchTerminal::InstallStopHandlers();

  const double duration = f.once && f.duration_s <= 0 ? 3.0 : f.duration_s;
  const int64_t start = NowUtime();
  const int64_t end = duration > 0 ? start + static_cast<int64_t>(duration * 1e6) : 0;
  const int64_t frame_us = static_cast<int64_t>(1e6 / f.refresh_hz);
  int64_t next_draw = 0, next_status = start + static_cast<int64_t>(f.status_every_s * 1e6);
  bool was_waiting = true;
  if (plain) say("watch: listening on " + f.lcm_url + " (Ctrl-C to stop)");

  for (;;) {
    bus.HandleOnce(20);
    bus.Drain();
    const int64_t now = NowUtime();
    if (WatchTerminal::StopRequested()) break;
    if (end && now >= end) break;
    render.decode_failures = bus.decode_failures();
    render.handler_failures = bus.handler_failures();
    if (terminal) {
      const int key = terminal->ReadKey();
      if (key == 'q' || key == 'Q' || key == 3) break;
      if (now >= next_draw) {
        terminal->Size(&render.cols, &render.rows);
        terminal->Draw(RenderWatch(state, now, render));
        next_draw = now + frame_us;
      }
    } else if (plain) {
      const bool waiting = state.Waiting(now);
      if (waiting && !was_waiting) {
        say(state.AnyData() ? "watch: waiting for data (the producer stopped?)"
                                     : "watch: waiting for data");
      }
      if (!waiting && was_waiting) say("watch: receiving");
      was_waiting = waiting;
      if (now >= next_status && !waiting) {
        say("watch: " + WatchStatusLine(state, now, render));
        next_status = now + static_cast<int64_t>(f.status_every_s * 1e6);
      }
    }
  }
  terminal.reset();  // restore the screen before anything else is printed
  if (f.once) {
    render.cols = 120;
    render.rows = 0;
    render.show_keys = false;
    for (const auto& line : RenderWatch(state, NowUtime(), render)) {
      std::string l = line;
      while (!l.empty() && l.back() == ' ') l.pop_back();
      std::printf("%s\n", l.c_str());
    }
    std::printf("height trace: %s\n", Sparkline(state, 60, render.unicode).c_str());
  } else if (plain) {
    say("watch: " + WatchStatusLine(state, NowUtime(), render));
  }
  std::fflush(stdout);
}

}  // namespace

void AddWatchCommand(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("watch", "Live terminal dashboard of a running session over LCM");
  auto f = std::make_shared<WatchFlags>();
  AddBusFlags(cmd, &f->lcm_url, &f->channels);
  cmd->add_flag("--plain", f->plain,
                "One line per event (for logs) instead of the dashboard; automatic without a "
                "terminal");
  cmd->add_flag("--once", f->once,
                "Listen for --duration seconds (default 3), print one snapshot, exit");
  cmd->add_option("--duration", f->duration_s, "Stop after this many seconds (0: until q/Ctrl-C)")
      ->capture_default_str()
      ->check(NonNegative());
  cmd->add_flag("--ascii", f->ascii, "ASCII only (no block characters in the height trace)");
  cmd->add_option("--refresh-hz", f->refresh_hz, "Dashboard redraws per second")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 60.0));
  cmd->add_option("--stale-after", f->config.stale_after_s,
                  "Seconds without a message before showing \"waiting for data\"")
      ->capture_default_str()
      ->check(Positive());
  cmd->footer(
      "Example (in a second terminal while `bouncefit run --out out/sample` runs):\n"
      "  bouncefit watch");
  cmd->callback([f] { RunWatch(*f); });
}

}  // namespace bouncefit::cli
