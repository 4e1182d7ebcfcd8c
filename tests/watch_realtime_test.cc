// `bouncefit watch` as a person uses it: in a real terminal (tmux), fed by real LCM UDP
// multicast traffic published from this process, read back from the screen.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "bouncefit/impact_t.hpp"
#include "msgs/lcm_bus.h"
#include "tests/report_fixture.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;
using testing::ScratchDir;

// A producer of the five channels for a ball dropped from `drop_m` with restitution e,
// seen at 120 fps by a camera with 400 px/m and the floor line at 460 px.
class Producer {
 public:
  Producer(const std::string& url, double drop_m, double fit_value,
           std::string peak_channel = "BOUNCE_PEAK")
      : bus_(url), drop_m_(drop_m), fit_value_(fit_value), peak_channel_(std::move(peak_channel)) {
    truth_.release_height_m = drop_m;
    truth_.release_t_s = 0.05;
  }

  // Publishes `seconds` of stream, paced at `speed` x real time: the calibration at 0.3 s,
  // each apex 50 ms after it happened, a fit update after each rebound.
  void Run(double seconds, double speed) {
    const int64_t t0 = 1'700'000'000'000'000;
    // Apexes in closed form.
    std::vector<double> apex_t{truth_.release_t_s}, apex_h{drop_m_}, impact_t_s;
    double t = truth_.release_t_s + std::sqrt(2 * drop_m_ / truth_.g);
    double v = std::sqrt(2 * truth_.g * drop_m_);
    while (t < seconds) {
      impact_t_s.push_back(t);
      v *= truth_.restitution;
      apex_t.push_back(t + v / truth_.g);
      apex_h.push_back(v * v / (2 * truth_.g));
      t += 2 * v / truth_.g;
    }
    size_t next_peak = 0, next_impact = 0;
    bool calibrated = false;
    const auto wall0 = std::chrono::steady_clock::now();
    const int frames = static_cast<int>(seconds * 120);
    for (int f = 0; f < frames; ++f) {
      const double ts = f / 120.0;
      const int64_t utime = t0 + static_cast<int64_t>(ts * 1e6);
      std::this_thread::sleep_until(wall0 + std::chrono::microseconds(
                                                static_cast<int64_t>(ts / speed * 1e6)));
      ball_box_t box{};
      box.utime = utime;
      box.frame = f;
      box.found = true;
      const double h = testing::FixtureHeight(truth_, truth_.restitution, ts);
      box.w = box.h = 16;
      box.cx = 320;
      box.cy = static_cast<float>(460 - h * 400 - 8);
      box.x = box.cx - 8;
      box.y = box.cy - 8;
      box.radius_px = 8;
      box.aspect_ratio = 1;
      box.score = 1;
      bus_.Publish("BALL_BOX", box);
      if (!calibrated && ts >= 0.3) {
        calibration_t c{};
        c.utime = utime;
        c.px_per_m = 400;
        c.px_per_m_sigma = 1.25;
        c.floor_px = 460;
        c.floor_sigma_px = 0.5;
        c.method = "free-fall";
        c.samples = 36;
        bus_.Publish("CALIBRATION", c);
        calibrated = true;
      }
      // Each impact 10 ms after it happened: heard and seen, but the second only heard.
      while (next_impact < impact_t_s.size() && impact_t_s[next_impact] + 0.01 <= ts) {
        impact_t m{};
        m.utime = t0 + static_cast<int64_t>(impact_t_s[next_impact] * 1e6);
        m.index = static_cast<int32_t>(next_impact);
        m.source = next_impact == 1 ? "audio" : "both";
        m.strength = 0.25;
        m.confidence = 0.9;
        bus_.Publish("IMPACT", m);
        ++next_impact;
      }
      while (next_peak < apex_t.size() && apex_t[next_peak] + 0.05 <= ts) {
        bounce_peak_t p{};
        p.utime = utime;
        p.bounce = p.live_bounce = static_cast<int32_t>(next_peak);
        p.apex_utime = t0 + static_cast<int64_t>(apex_t[next_peak] * 1e6);
        p.height_m = apex_h[next_peak];
        p.height_px = apex_h[next_peak] * 400;
        p.height_sigma_m = 0.003;
        p.flight_height_m = NAN;
        p.emitted_utime = utime;
        bus_.Publish(peak_channel_, p);
        if (next_peak >= 1) PublishFit(utime, static_cast<int>(next_peak), apex_h);
        ++next_peak;
      }
    }
  }

  // A message that does not decode as a ball_box_t.
  void PublishGarbage() {
    const char junk[] = "not an lcm message";
    bus_.raw().publish("BALL_BOX", junk, sizeof junk);
  }

 private:
  void PublishFit(int64_t utime, int after, const std::vector<double>& apex_h) {
    if (after == 1) {  // a second model, fitted once
      fit_update_t soft{};
      soft.utime = utime;
      soft.after_bounce = 1;
      soft.model = "bullet-softbody";
      soft.method = "live-gauss-newton";
      soft.names = {"linear_stiffness"};
      soft.values = {0.5};
      soft.sigmas = {0.1};
      soft.identifiable = {true};
      soft.num_coeffs = 1;
      soft.residual_m = 0.0125;
      bus_.Publish("FIT_UPDATE", soft);
    }
    fit_update_t m{};
    m.utime = utime;
    m.start_bounce = 0;
    m.after_bounce = after;
    m.final = false;
    m.model = "point-mass";
    m.method = "nlopt-bobyqa";
    m.names = {"restitution", "drag_coefficient"};
    m.values = {fit_value_, 0.4567};
    m.sigmas = {0.002, NAN};
    m.identifiable = {true, false};
    m.num_coeffs = 2;
    for (int i = 1; i <= after; ++i) {
      m.recorded_m.push_back(apex_h[i]);
      m.simulated_m.push_back(apex_h[i] * 0.99);
    }
    m.num_bounces = after;
    m.residual_m = 0.0042;
    m.evaluations = 37;
    m.wall_time_s = 0.25;
    m.time_step_s = 1.0 / 120;
    m.iterations = 4;
    bus_.Publish("FIT_UPDATE", m);
  }

  LcmBus bus_;
  testing::ReportFixtureTruth truth_;
  double drop_m_, fit_value_;
  std::string peak_channel_;
};

// A private tmux server (its own socket), killed at the end of the test.
class Tmux {
 public:
  Tmux() : socket_("bouncefit-watch-" + std::to_string(::getpid())) {}
  ~Tmux() { RunCommand(Cmd("kill-server"), nullptr); }
  std::string Cmd(const std::string& args) const {
    return "LANG=C.UTF-8 tmux -L '" + socket_ + "' " + args;
  }
  std::string Capture() const {
    std::string out;
    RunCommand(Cmd("capture-pane -p -t w"), &out);
    return out;
  }
  // Polls the screen until it contains `text` or `timeout_s` passes.
  bool WaitFor(const std::string& text, double timeout_s, std::string* screen = nullptr) const {
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(static_cast<int>(timeout_s * 1000));
    std::string s;
    do {
      s = Capture();
      if (s.find(text) != std::string::npos) {
        if (screen) *screen = s;
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    } while (std::chrono::steady_clock::now() < end);
    if (screen) *screen = s;
    return false;
  }

 private:
  std::string socket_;
};

bool WaitForFile(const fs::path& p, double timeout_s, std::string* content) {
  const auto end = std::chrono::steady_clock::now() +
                   std::chrono::milliseconds(static_cast<int>(timeout_s * 1000));
  do {
    std::ifstream in(p);
    std::string s;
    if (in && std::getline(in, s) && !s.empty()) {
      *content = s;
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  } while (std::chrono::steady_clock::now() < end);
  return false;
}

class WatchInTmux : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string out;
    if (RunCommand("command -v tmux", &out) != 0) GTEST_SKIP() << "tmux not installed";
    dir_ = ScratchDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    url_ = testing::UniqueUdpmUrl();
  }
  // Starts watch in a 120x40 tmux window; its exit status lands in dir_/exit_status.
  void StartWatch() {
    const std::string inner = BouncefitExe() + " watch --lcm-url '" + url_ +
                              "' --stale-after 1; echo $? > '" + (dir_ / "exit_status").string() +
                              "'; sleep 30";
    std::string out;
    ASSERT_EQ(RunCommand(tmux_.Cmd("new-session -d -s w -x 120 -y 40 \"" + inner + "\""), &out), 0)
        << out;
    std::string screen;
    ASSERT_TRUE(tmux_.WaitFor("waiting for data (nothing received yet)", 10, &screen)) << screen;
  }
  Tmux tmux_;
  fs::path dir_;
  std::string url_;
};

TEST_F(WatchInTmux, ShowsPeaksAndCoefficientsSurvivesRestartAndQuitsOnQ) {
  StartWatch();
  std::string screen;
  {
    // 3 s of stream in real time, on another thread: the screen is read while it runs.
    std::atomic<bool> done{false};
    std::thread producer_thread([&] {
      Producer producer(url_, 1.0, 0.8123);
      producer.PublishGarbage();
      producer.Run(3.0, 1.0);
      done = true;
    });
    // Bounce 1 (1.0 m * 0.8^2) shows up in place while the producer is still publishing.
    const bool first_peak = tmux_.WaitFor("0.6400", 3, &screen);
    const bool while_live = !done;
    const bool second_fit = tmux_.WaitFor("fit after bounce 2", 3, &screen);
    producer_thread.join();
    ASSERT_TRUE(first_peak) << screen;
    EXPECT_TRUE(while_live) << "the peak appeared only after the producer finished";
    ASSERT_TRUE(second_fit) << screen;
    std::ofstream(dir_ / "dashboard.txt") << screen;  // for a look by eye
    EXPECT_NE(screen.find("1.0000"), std::string::npos) << screen;  // release height
    EXPECT_NE(screen.find("0.4096"), std::string::npos) << screen;  // bounce 2
    // Beside it, the latest fit's simulated apex of bounce 2 (0.99 of it), paired by number.
    const size_t row = screen.rfind("\n", screen.find("0.4096")) + 1;
    const std::string bounce2 = screen.substr(row, screen.find("\n", row) - row);
    EXPECT_NE(bounce2.find("0.4055"), std::string::npos) << bounce2;
    EXPECT_NE(screen.find("0.800"), std::string::npos) << screen;   // restitution from heights
    EXPECT_NE(screen.find("restitution"), std::string::npos) << screen;
    EXPECT_NE(screen.find("0.8123"), std::string::npos) << screen;
    EXPECT_NE(screen.find("drag_coefficient (n/i)"), std::string::npos) << screen;
    EXPECT_NE(screen.find("0.6400    3.00"), std::string::npos) << "height sigma in mm:\n" << screen;
    // The other model's latest fit stays visible in one line.
    EXPECT_NE(screen.find("also bullet-softbody after #1: residual 12.50 mm"), std::string::npos)
        << screen;
    EXPECT_NE(screen.find("0.4567"), std::string::npos) << screen;
    EXPECT_NE(screen.find("residual 4.20 mm"), std::string::npos) << screen;
    EXPECT_NE(screen.find("400.00 +- 1.25 px/m"), std::string::npos) << screen;
    EXPECT_NE(screen.find("height of the ball bottom above the floor (m)"), std::string::npos);
    // The height trace is drawn: full blocks under the arcs, and the top row (near 1 m)
    // reached only by the release.
    size_t blocks = 0;
    for (size_t at = screen.find("\u2588"); at != std::string::npos;
         at = screen.find("\u2588", at + 1)) {
      ++blocks;
    }
    EXPECT_GT(blocks, 100u) << screen;
    EXPECT_NE(screen.find("decode failures 1"), std::string::npos) << screen;
    EXPECT_NE(screen.find("[LIVE]"), std::string::npos) << screen;
    std::smatch rate;
    ASSERT_TRUE(std::regex_search(screen, rate, std::regex("BALL_BOX ([0-9.]+)/s"))) << screen;
    EXPECT_NEAR(std::stod(rate[1].str()), 120, 15) << screen;  // published at 120 per second
  }
  // The producer stopped: the dashboard says so, and keeps what it had.
  ASSERT_TRUE(tmux_.WaitFor("waiting for data (no message for", 4, &screen)) << screen;
  EXPECT_NE(screen.find("0.6400"), std::string::npos) << screen;

  // A new producer (frames from 0 again, another drop): a new stream on the same screen.
  {
    Producer producer(url_, 0.5, 0.7001);
    producer.Run(1.5, 2.0);
    ASSERT_TRUE(tmux_.WaitFor("restarts 1", 3, &screen)) << screen;
    ASSERT_TRUE(tmux_.WaitFor("0.3200", 3, &screen)) << screen;  // 0.5 m * 0.8^2
    EXPECT_NE(screen.find("0.7001"), std::string::npos) << screen;
    EXPECT_EQ(screen.find("0.6400"), std::string::npos) << "old stream's peaks kept:\n" << screen;
  }

  std::string out;
  ASSERT_EQ(RunCommand(tmux_.Cmd("send-keys -t w q"), &out), 0) << out;
  std::string status;
  ASSERT_TRUE(WaitForFile(dir_ / "exit_status", 5, &status)) << tmux_.Capture();
  EXPECT_EQ(status, "0");
  // The terminal is given back: the dashboard (alternate screen) is gone.
  screen = tmux_.Capture();
  EXPECT_EQ(screen.find("bounces and coefficients"), std::string::npos) << screen;
}

TEST_F(WatchInTmux, CtrlCExitsCleanly) {
  StartWatch();
  std::string out;
  ASSERT_EQ(RunCommand(tmux_.Cmd("send-keys -t w C-c"), &out), 0) << out;
  std::string status;
  ASSERT_TRUE(WaitForFile(dir_ / "exit_status", 5, &status)) << tmux_.Capture();
  EXPECT_EQ(status, "0");
  EXPECT_EQ(tmux_.Capture().find("waiting for data"), std::string::npos) << tmux_.Capture();
}

TEST(WatchPlain, WithoutATerminalPrintsEventLines) {
  const std::string url = testing::UniqueUdpmUrl();
  std::string out;
  std::thread producer_thread([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    Producer producer(url, 1.0, 0.8123);
    producer.Run(2.0, 2.0);
  });
  const int rc = RunCommand(BouncefitExe() + " watch --lcm-url '" + url +
                                "' --duration 3.5 --stale-after 1 < /dev/null | cat",
                            &out);
  producer_thread.join();
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("watch: listening on"), std::string::npos) << out;
  EXPECT_NE(out.find("calibration  400.00 +- 1.25 px/m"), std::string::npos) << out;
  EXPECT_NE(out.find("height 0.6400 m"), std::string::npos) << out;
  EXPECT_NE(out.find("restitution=0.8123"), std::string::npos) << out;
  // Impacts as they arrive (the first at 0.05 s + 0.452 s of fall).
  EXPECT_NE(out.find("impact #0   t=  0.50"), std::string::npos) << out;
  EXPECT_NE(out.find("heard and seen  strength 0.2500 (full scale 1)  confidence 0.90"),
            std::string::npos) << out;
  EXPECT_NE(out.find("impact #1 "), std::string::npos) << out;
  EXPECT_EQ(out.find("\x1b["), std::string::npos) << "escape codes in plain output";
  // The producer stops 1.7 s in: the log says so.
  const auto receiving = out.find("watch: receiving");
  const auto stopped = out.find("watch: waiting for data (the producer stopped?)");
  ASSERT_NE(receiving, std::string::npos) << out;
  ASSERT_NE(stopped, std::string::npos) << out;
  EXPECT_LT(receiving, stopped);
}

TEST(WatchPlain, OnceGivesOneSnapshot) {
  const std::string url = testing::UniqueUdpmUrl();
  std::string out;
  std::thread producer_thread([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    Producer producer(url, 1.0, 0.8123, "MY_PEAKS");  // a channel override
    producer.Run(2.0, 2.0);
  });
  const int rc = RunCommand(BouncefitExe() +
                                " watch --once --ascii --duration 2.5 --bounce-peak-channel MY_PEAKS "
                                "--lcm-url '" + url + "'",
                            &out);
  producer_thread.join();
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("0.6400"), std::string::npos) << out;
  EXPECT_NE(out.find("restitution"), std::string::npos) << out;
  EXPECT_NE(out.find("height trace: "), std::string::npos) << out;
  EXPECT_NE(out.find('#'), std::string::npos) << "no ASCII trace:\n" << out;
  EXPECT_NE(out.find("MY_PEAKS "), std::string::npos) << out;
  // The impacts listed and marked under the chart.
  std::smatch impacts;
  ASSERT_TRUE(std::regex_search(out, impacts, std::regex("impacts  ([0-9]+): ([0-9]+) heard"))) << out;
  EXPECT_GE(std::stoi(impacts[1].str()), 2) << out;
  EXPECT_EQ(impacts[1].str(), impacts[2].str()) << out;
  std::smatch row;
  ASSERT_TRUE(std::regex_search(out, row, std::regex("\nimpacts  ( *\\*[ *]*)\n"))) << out;
  EXPECT_EQ(out.find("\u2588"), std::string::npos) << "--ascii drew blocks:\n" << out;
}

}  // namespace
}  // namespace bouncefit
