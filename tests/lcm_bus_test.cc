// Every message type crosses the bus intact: in process over memq://, and between two
// processes over UDP multicast on loopback (ttl=0).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "msgs/channels.h"
#include "msgs/lcm_bus.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

ball_box_t SampleBox() {
  ball_box_t m{};
  m.utime = 1234567;
  m.frame = 42;
  m.found = true;
  m.x = 10.5f; m.y = 20.25f; m.w = 30; m.h = 31;
  m.cx = 25.5f; m.cy = 35.75f; m.radius_px = 15.2f;
  m.pixel_count = 700; m.aspect_ratio = 30.0f / 31; m.score = 0.9f;
  return m;
}

calibration_t SampleCalibration() {
  calibration_t m{};
  m.utime = 2000000; m.px_per_m = 412.5; m.px_per_m_sigma = 0.8;
  m.roll_rad = 0.017; m.roll_sigma_rad = 0.001; m.floor_px = 455.2; m.floor_sigma_px = 0.3;
  m.method = "free-fall"; m.samples = 57;
  return m;
}

bounce_peak_t SamplePeak() {
  bounce_peak_t m{};
  m.utime = 3000000; m.sequence = 0; m.bounce = 2; m.apex_utime = 2990000;
  m.height_m = 0.612; m.height_px = 252.4; m.height_sigma_m = 0.001;
  m.flight_height_m = 0.609; m.impact_before_utime = 2600000; m.impact_after_utime = 0;
  m.emitted_utime = 3000000;
  return m;
}

fit_update_t SampleFit() {
  fit_update_t m{};
  m.utime = 4000000; m.sequence = 0; m.after_bounce = 3; m.final = false;
  m.model = "bullet-softbody"; m.method = "nlopt-bobyqa";
  m.num_coeffs = 2;
  m.names = {"linear_stiffness", "pressure"};
  m.values = {0.5, 120.0};
  m.sigmas = {0.01, NAN};
  m.identifiable = {true, false};
  m.num_bounces = 3;
  m.recorded_m = {0.8, 0.64, 0.51};
  m.simulated_m = {0.79, 0.65, 0.5};
  m.residual_m = 0.01; m.evaluations = 55; m.wall_time_s = 0.42;
  m.time_step_s = 1.0 / 480; m.iterations = 4;
  return m;
}

template <class Msg>
std::vector<uint8_t> Encode(const Msg& m) {
  std::vector<uint8_t> buf(m.getEncodedSize());
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

// Encoded bytes are a complete, order-sensitive comparison of two messages.
template <class Msg>
void ExpectSame(const Msg& a, const Msg& b) { EXPECT_EQ(Encode(a), Encode(b)); }

struct Received {
  std::vector<ball_box_t> boxes;
  std::vector<calibration_t> calibrations;
  std::vector<bounce_peak_t> peaks;
  std::vector<fit_update_t> fits;
  size_t total() const { return boxes.size() + calibrations.size() + peaks.size() + fits.size(); }
};

void SubscribeAll(LcmBus& bus, const Channels& ch, Received& r) {
  bus.Subscribe<ball_box_t>(ch.ball_box, [&r](const ball_box_t& m) { r.boxes.push_back(m); });
  bus.Subscribe<calibration_t>(ch.calibration,
                               [&r](const calibration_t& m) { r.calibrations.push_back(m); });
  bus.Subscribe<bounce_peak_t>(ch.bounce_peak,
                               [&r](const bounce_peak_t& m) { r.peaks.push_back(m); });
  bus.Subscribe<fit_update_t>(ch.fit_update, [&r](const fit_update_t& m) { r.fits.push_back(m); });
}

void PublishAll(LcmBus& bus, const Channels& ch) {
  bus.Publish(ch.ball_box, SampleBox());
  bus.Publish(ch.calibration, SampleCalibration());
  bus.Publish(ch.bounce_peak, SamplePeak());
  bus.Publish(ch.fit_update, SampleFit());
}

void ExpectAllSamples(const Received& r) {
  ASSERT_EQ(r.boxes.size(), 1u);
  ASSERT_EQ(r.calibrations.size(), 1u);
  ASSERT_EQ(r.peaks.size(), 1u);
  ASSERT_EQ(r.fits.size(), 1u);
  ExpectSame(r.boxes[0], SampleBox());
  ExpectSame(r.calibrations[0], SampleCalibration());
  ExpectSame(r.peaks[0], SamplePeak());
  ExpectSame(r.fits[0], SampleFit());
  EXPECT_EQ(r.fits[0].names[1], "pressure");
  EXPECT_TRUE(std::isnan(r.fits[0].sigmas[1]));
}

TEST(Msgs, EveryTypeRoundTripsOverMemq) {
  LcmBus bus("memq://");
  Channels ch;
  Received r;
  SubscribeAll(bus, ch, r);
  PublishAll(bus, ch);
  bus.Drain();
  ExpectAllSamples(r);
}

TEST(Msgs, ChannelNamesAreOverridable) {
  LcmBus bus("memq://");
  Channels ch;
  ch.ball_box = "MY_BOX";
  Received r;
  SubscribeAll(bus, ch, r);
  bus.Publish("BALL_BOX", SampleBox());  // the default name: nobody listens
  bus.Publish("MY_BOX", SampleBox());
  bus.Drain();
  EXPECT_EQ(r.boxes.size(), 1u);
}

TEST(Msgs, GarbledPacketIsCountedNotDelivered) {
  LcmBus bus("memq://");
  Channels ch;
  Received r;
  SubscribeAll(bus, ch, r);
  const uint8_t garbage[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  bus.raw().publish(ch.fit_update, garbage, sizeof garbage);
  bus.Drain();
  EXPECT_EQ(r.total(), 0u);
  EXPECT_EQ(bus.decode_failures(), 1);
  EXPECT_NE(bus.last_error().find(ch.fit_update), std::string::npos);
}

TEST(Msgs, ThrowingHandlerIsContained) {
  LcmBus bus("memq://");
  bus.Subscribe<ball_box_t>("BALL_BOX",
                            [](const ball_box_t&) { throw std::runtime_error("boom"); });
  bus.Publish("BALL_BOX", SampleBox());
  bus.Drain();
  EXPECT_EQ(bus.handler_failures(), 1);
  EXPECT_NE(bus.last_error().find("boom"), std::string::npos);
}

TEST(Msgs, EveryTypeCrossesProcessesOverUdpmLoopback) {
  const std::string url = testing::UniqueUdpmUrl();
  Channels ch;
  LcmBus bus(url);
  Received r;
  SubscribeAll(bus, ch, r);

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The child is a separate process with its own LCM instance: it only publishes.
    try {
      LcmBus tx(url);
      PublishAll(tx, ch);
    } catch (...) {
      ::_exit(3);
    }
    ::_exit(0);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (r.total() < 4 && std::chrono::steady_clock::now() < deadline) bus.HandleOnce(100);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  ExpectAllSamples(r);
}

}  // namespace
}  // namespace bouncefit
