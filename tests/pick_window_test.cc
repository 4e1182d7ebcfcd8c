// --pick-window as a user drives it: a virtual X server (Xvfb), bouncefit's window on the first
// frame of a rendered clip, scripted clicks (xdotool: XTEST events at the window's own
// coordinates), then the run's tracking against the clip's truth.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "synth/synth_clip.h"
#include "tests/test_support.h"
#include "track/pick_view.h"

// Last: Xlib's macros (None, Bool, Status) would break the headers above.
#include <X11/Xlib.h>

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;

bool Installed(const std::string& program) {
  std::string out;
  return RunCommand("command -v " + program, &out) == 0;
}

// Forks `argv`-less shell `command` with DISPLAY set; stdout and stderr into `log`.
pid_t Spawn(const std::string& command, const std::string& display, const fs::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setenv("DISPLAY", display.c_str(), 1);
    const fs::path runtime = log.parent_path() / "xdg-runtime";
    fs::create_directories(runtime);
    ::chmod(runtime.c_str(), 0700);
    ::setenv("XDG_RUNTIME_DIR", runtime.c_str(), 1);  // Qt warns without one
    const std::string line = "exec " + command + " > '" + log.string() + "' 2>&1";
    ::execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// Exit status of `pid`, or -1 (and the process killed) after `timeout`. Before the kill, what
// the process was doing goes next to `log`: its threads' stacks (when gdb is installed) and a
// picture of the display.
int WaitFor(pid_t pid, std::chrono::seconds timeout, const std::string& display, const fs::path& log) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::string out;
  const std::string stem = log.string();
  RunCommand("command -v gdb >/dev/null && timeout 60 gdb -p " + std::to_string(pid) +
                 " -batch -ex 'thread apply all bt' > '" + stem + ".stacks.txt' 2>&1",
             &out);
  RunCommand("timeout 20 ffmpeg -loglevel error -y -f x11grab -video_size 1280x1024 -i " + display +
                 " -frames:v 1 '" + stem + ".screen.png'",
             &out);
  std::printf("timed out: %s\nstacks and screen in %s.*\n", testing::ReadFile(log).c_str(), stem.c_str());
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

// A virtual X server on a display number it picks itself (-displayfd: never one in use).
class VirtualDisplay {
 public:
  VirtualDisplay() {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(fds[0]);
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, 1), ::dup2(null, 2);
      const std::string fd = std::to_string(fds[1]);
      ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1280x1024x24",
               "-nolisten", "tcp", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    pollfd p{fds[0], POLLIN, 0};
    std::string number;
    char ch;
    while (::poll(&p, 1, 10000) > 0 && ::read(fds[0], &ch, 1) == 1 && ch != '\n') number += ch;
    ::close(fds[0]);
    if (!number.empty()) name_ = ":" + number;
  }
  ~VirtualDisplay() {
    if (pid_ > 0) ::kill(pid_, SIGTERM), ::waitpid(pid_, nullptr, 0);
  }
  const std::string& name() const { return name_; }

 private:
  pid_t pid_ = -1;
  std::string name_;
};

// xdotool on `display`, bounded in time; `args` go to the window `id`, given the keyboard focus
// first (with no window manager nobody else gives it).
int Xdotool(const std::string& display, const std::string& id, const std::string& args,
            std::string* out) {
  return RunCommand("DISPLAY=" + display + " timeout 30 xdotool windowfocus --sync " + id + " " + args, out);
}

bool WaitForViewSize(const std::string& display, const std::string& id, cv::Size size);

// Waits for bouncefit's window, sized for the view of a `frame` sized frame, and returns its X id
// ("" if it never came).
std::string PickWindowId(const std::string& display, cv::Size frame) {
  std::string out;
  if (RunCommand("DISPLAY=" + display + " timeout 30 xdotool search --sync --onlyvisible --name 'pick the ball'",
                 &out) != 0)
    return "";
  std::istringstream in(out);
  std::string id;
  in >> id;
  const PickLayout l = LayoutPickView(frame, PickViewParams{});
  return WaitForViewSize(display, id, l.size) ? id : "";
}

// What a window manager does when its close button is pressed: ask the client, politely.
void CloseLikeAWindowManager(const std::string& display, const std::string& id) {
  Display* d = XOpenDisplay(display.c_str());
  ASSERT_NE(d, nullptr);
  XEvent e{};
  e.xclient.type = ClientMessage;
  e.xclient.window = std::stoul(id);
  e.xclient.message_type = XInternAtom(d, "WM_PROTOCOLS", False);
  e.xclient.format = 32;
  e.xclient.data.l[0] = static_cast<long>(XInternAtom(d, "WM_DELETE_WINDOW", False));
  e.xclient.data.l[1] = CurrentTime;
  XSendEvent(d, e.xclient.window, False, NoEventMask, &e);
  XCloseDisplay(d);
}

// Waits until the window has the view's size: Qt maps it first and sizes it to the image
// after, and clicks sent in between land elsewhere (seen once in six runs on a loaded machine).
bool WaitForViewSize(const std::string& display, const std::string& id, cv::Size size) {
  const std::string want = "Geometry: " + std::to_string(size.width) + "x" + std::to_string(size.height);
  std::string out;
  for (int i = 0; i < 200; ++i) {
    RunCommand("DISPLAY=" + display + " timeout 10 xdotool getwindowgeometry " + id, &out);
    if (out.find(want) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::printf("window %s never reached the view's size (%s); last: %s\n", id.c_str(), want.c_str(), out.c_str());
  return false;
}

std::string At(const PickLayout& l, double x, double y) {
  const cv::Point v = l.ToView({x, y});
  return std::to_string(v.x) + " " + std::to_string(v.y);
}

SynthClipResult RenderClip(const fs::path& dir, double duration_s, cv::Size size = {640, 480}) {
  SynthClipConfig c;
  c.width = size.width, c.height = size.height;
  c.ball = *FindBallPreset("pingpong");
  c.noise_sigma = 3;
  c.hold_s = 0.2;
  c.duration_s = duration_s;
  c.distractor = true;  // a sphere of the ball's hue on the floor, left out by the region
  c.out = dir / "drop.avi";
  return RenderSynthClip(c);
}

// `bouncefit run` on `clip` into `out` with the window, as fast as it can, without a fit.
std::string RunWithWindow(const fs::path& clip, const fs::path& out) {
  return BouncefitExe() + " run " + clip.string() + " --out " + out.string() +
         " --speed 0 --no-fit --lcm-url memq:// --pick-window";
}

// `bouncefit capture` replaying `clip` with the window, as fast as it can; `more`: other flags.
std::string CaptureWithWindow(const fs::path& clip, const std::string& more) {
  return BouncefitExe() + " capture --replay " + clip.string() + " --speed 0 --lcm-url memq:// --pick-window " + more;
}

#define REQUIRE_XVFB()                                                                          \
  if (!Installed("Xvfb") || !Installed("xdotool"))                                             \
    GTEST_SKIP() << "Xvfb or xdotool absent: bash scripts/setup installs them (Debian xvfb, xdotool)";

// Click the ball, drag a region that leaves the floor's lookalike out, Enter: the run tracks
// the ball with that colour and region, to the synth truth.
TEST(PickWindow, ClickDragEnterThenTracksTheBall) {
  REQUIRE_XVFB();
  const fs::path dir = testing::ScratchDir("pick_run");
  const SynthClipResult clip = RenderClip(dir, 1.6);
  const SynthTruthFrame& t0 = clip.truth.frames[0];
  VirtualDisplay x;
  ASSERT_FALSE(x.name().empty()) << "Xvfb did not start";

  const fs::path out = dir / "out", log = dir / "run.txt";
  const pid_t run = Spawn(RunWithWindow(clip.clip_path, out), x.name(), log);
  const std::string id = PickWindowId(x.name(), {clip.truth.width, clip.truth.height});
  ASSERT_FALSE(id.empty()) << "no window appeared: " << testing::ReadFile(log);
  // The region: the ball's column, 100 px either side of it, floor included; the lookalike on
  // the floor at 80% of the width stays outside.
  const double x0 = t0.cx - 100, y0 = 2, x1 = t0.cx + 100, y1 = clip.truth.height - 3;
  const PickLayout l = LayoutPickView({clip.truth.width, clip.truth.height}, PickViewParams{});
  std::string xo;
  const std::string w = " --window " + id + " ";
  ASSERT_EQ(Xdotool(x.name(), id,
                    "mousemove" + w + At(l, t0.cx, t0.cy) + " click 1 sleep 0.2" +
                        " mousemove" + w + At(l, x0, y0) + " mousedown 1 sleep 0.1" +
                        " mousemove" + w + At(l, t0.cx, 200) + " sleep 0.1" +
                        " mousemove" + w + At(l, x1, y1) + " sleep 0.1 mouseup 1 sleep 0.2 key Return",
                    &xo),
            0)
      << xo;
  const int rc = WaitFor(run, std::chrono::seconds(90), x.name(), log);
  const std::string text = testing::ReadFile(log);
  ASSERT_EQ(rc, 0) << text;
  EXPECT_NE(text.find("pick-window: ball at " + std::to_string(std::lround(t0.cx)) + "," +
                      std::to_string(std::lround(t0.cy))),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("region " + std::to_string(std::lround(x0)) + "," + std::to_string(std::lround(y0))),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("picked in the window"), std::string::npos) << text;

  // Every frame with the ball in view tracked, within 0.3 px RMS of the truth.
  std::ifstream track(out / "track.csv");
  std::string line;
  std::getline(track, line);
  int in_view = 0, found = 0;
  double sum2 = 0;
  for (const SynthTruthFrame& t : clip.truth.frames) {
    ASSERT_TRUE(std::getline(track, line)) << "track.csv ends at frame " << t.index;
    int frame, ok;
    double ts, cx, cy;
    ASSERT_EQ(std::sscanf(line.c_str(), "%d,%lf,%d,%lf,%lf", &frame, &ts, &ok, &cx, &cy), 5) << line;
    if (!t.fully_in_view) continue;
    ++in_view;
    if (!ok) continue;
    ++found;
    sum2 += (cx - t.cx) * (cx - t.cx) + (cy - t.cy) * (cy - t.cy);
  }
  ASSERT_GT(in_view, 100);
  EXPECT_EQ(found, in_view);
  const double rms = std::sqrt(sum2 / std::max(found, 1));
  std::printf("pick-window run: %d of %d frames with the ball in view found, centre error %.3f px RMS\n", found,
              in_view, rms);
  EXPECT_LE(rms, 0.3);
}

// `capture` takes the same window; a click, + twice (a wider colour tolerance) and space.
TEST(PickWindow, CaptureTakesItToo) {
  REQUIRE_XVFB();
  const fs::path dir = testing::ScratchDir("pick_capture");
  const SynthClipResult clip = RenderClip(dir, 0.6);
  const SynthTruthFrame& t0 = clip.truth.frames[0];
  VirtualDisplay x;
  ASSERT_FALSE(x.name().empty()) << "Xvfb did not start";
  const fs::path log = dir / "capture.txt";
  const pid_t cap = Spawn(CaptureWithWindow(clip.clip_path, "--max-frames 60"), x.name(), log);
  const std::string id = PickWindowId(x.name(), {clip.truth.width, clip.truth.height});
  ASSERT_FALSE(id.empty()) << "no window appeared: " << testing::ReadFile(log);
  const PickLayout l = LayoutPickView({clip.truth.width, clip.truth.height}, PickViewParams{});
  std::string xo;
  ASSERT_EQ(Xdotool(x.name(), id, "mousemove --window " + id + " " + At(l, t0.cx, t0.cy) +
                                  " click 1 sleep 0.2 key plus sleep 0.1 key plus sleep 0.1 key space",
                    &xo),
            0)
      << xo;
  ASSERT_EQ(WaitFor(cap, std::chrono::seconds(60), x.name(), log), 0) << testing::ReadFile(log);
  const std::string text = testing::ReadFile(log);
  EXPECT_NE(text.find("capture: pick-window: ball at"), std::string::npos) << text;
  EXPECT_NE(text.find("tolerance 0.70"), std::string::npos) << "+ twice: 0.45 x 1.25^2\n" << text;
  EXPECT_NE(text.find("60 frames, 0 dropped, 60 found"), std::string::npos) << text;
}

// A 1920x1080 frame is shown at half size: a click on the ball's picture is the ball's pixel.
TEST(PickWindow, LargeFrameShrinksAndClicksMapBack) {
  REQUIRE_XVFB();
  const fs::path dir = testing::ScratchDir("pick_hd");
  const SynthClipResult clip = RenderClip(dir, 0.4, {1920, 1080});
  const SynthTruthFrame& t0 = clip.truth.frames[0];
  VirtualDisplay x;
  ASSERT_FALSE(x.name().empty()) << "Xvfb did not start";
  const fs::path log = dir / "capture.txt";
  const pid_t cap = Spawn(CaptureWithWindow(clip.clip_path, "--max-frames 30"), x.name(), log);
  const std::string id = PickWindowId(x.name(), {clip.truth.width, clip.truth.height});
  ASSERT_FALSE(id.empty()) << "no window appeared: " << testing::ReadFile(log);
  const PickLayout l = LayoutPickView({clip.truth.width, clip.truth.height}, PickViewParams{});
  ASSERT_LT(l.scale, 0.6);
  std::string xo;
  ASSERT_EQ(Xdotool(x.name(), id, "mousemove --window " + id + " " + At(l, t0.cx, t0.cy) +
                                      " click 1 sleep 0.2 key Return",
                    &xo),
            0)
      << xo;
  ASSERT_EQ(WaitFor(cap, std::chrono::seconds(60), x.name(), log), 0) << testing::ReadFile(log);
  const std::string text = testing::ReadFile(log);
  double px = 0, py = 0;
  const size_t at = text.find("pick-window: ball at ");
  ASSERT_NE(at, std::string::npos) << text;
  ASSERT_EQ(std::sscanf(text.c_str() + at, "pick-window: ball at %lf,%lf", &px, &py), 2) << text;
  EXPECT_NEAR(px, t0.cx, 1.5 / l.scale);
  EXPECT_NEAR(py, t0.cy, 1.5 / l.scale);
  EXPECT_NE(text.find("30 frames, 0 dropped, 30 found"), std::string::npos) << text;
}

// Esc cancels: a one-line error, a non-zero exit, no output directory.
TEST(PickWindow, EscCancelsAndWritesNothing) {
  REQUIRE_XVFB();
  const fs::path dir = testing::ScratchDir("pick_esc");
  const SynthClipResult clip = RenderClip(dir, 0.6);
  VirtualDisplay x;
  ASSERT_FALSE(x.name().empty()) << "Xvfb did not start";
  const fs::path out = dir / "out", log = dir / "run.txt";
  const pid_t run = Spawn(RunWithWindow(clip.clip_path, out), x.name(), log);
  const std::string id = PickWindowId(x.name(), {clip.truth.width, clip.truth.height});
  ASSERT_FALSE(id.empty()) << "no window appeared: " << testing::ReadFile(log);
  std::string xo;
  // Enter before any click does not confirm; Esc then cancels.
  ASSERT_EQ(Xdotool(x.name(), id, "mousemove --window " + id + " 20 20 key Return sleep 0.3 key Escape", &xo), 0)
      << xo;
  EXPECT_EQ(WaitFor(run, std::chrono::seconds(30), x.name(), log), 1);
  const std::string text = testing::ReadFile(log);
  EXPECT_EQ(text, "bouncefit run: error: --pick-window: cancelled (Esc); nothing written\n");
  EXPECT_FALSE(fs::exists(out));
}

// Closing the window (its title bar's button) cancels too: no hang.
TEST(PickWindow, ClosingTheWindowCancels) {
  REQUIRE_XVFB();
  const fs::path dir = testing::ScratchDir("pick_close");
  const SynthClipResult clip = RenderClip(dir, 0.6);
  VirtualDisplay x;
  ASSERT_FALSE(x.name().empty()) << "Xvfb did not start";
  const fs::path log = dir / "capture.txt";
  const pid_t cap = Spawn(CaptureWithWindow(clip.clip_path, ""), x.name(), log);
  const std::string id = PickWindowId(x.name(), {clip.truth.width, clip.truth.height});
  ASSERT_FALSE(id.empty()) << "no window appeared: " << testing::ReadFile(log);
  CloseLikeAWindowManager(x.name(), id);
  EXPECT_EQ(WaitFor(cap, std::chrono::seconds(30), x.name(), log), 1);
  EXPECT_EQ(testing::ReadFile(log), "bouncefit capture: error: --pick-window: cancelled (the window was closed); nothing written\n");
}

// No display: a one-line error at once, before anything is written (no Xvfb needed).
TEST(PickWindow, NoDisplayFailsAtOnce) {
  const fs::path dir = testing::ScratchDir("pick_nodisplay");
  const fs::path out = dir / "out";
  std::string text;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(RunCommand("env -u DISPLAY " + BouncefitExe() + " run --out " + out.string() + " --pick-window",
                       &text),
            1);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  EXPECT_NE(text.find("DISPLAY is unset"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(out));
  // A display that does not answer is the same kind of error, not Qt's abort.
  EXPECT_EQ(RunCommand("DISPLAY=:1999 " + BouncefitExe() + " capture --replay /dev/null --pick-window", &text), 1);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  EXPECT_NE(text.find("cannot open the display"), std::string::npos) << text;
  // It excludes the other ways to give the colour.
  EXPECT_NE(RunCommand(BouncefitExe() + " run --pick 1,1 --pick-window", &text), 0);
  EXPECT_NE(text.find("excludes"), std::string::npos) << text;
}

}  // namespace
}  // namespace bouncefit
