// Real-time pacing against capture times, with an injected clock (no sleeping).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "replay/pacer.h"

namespace bouncefit {
namespace {

class FakeClock : public PacerClock {
 public:
  int64_t NowMicros() override { return now; }
  void SleepUntilMicros(int64_t deadline) override {
    sleeps.push_back(deadline);
    if (deadline > now) now = deadline;
  }
  int64_t now = 1000000;
  std::vector<int64_t> sleeps;
};

TEST(Pacer, ReleasesEachFrameAtItsCaptureTime) {
  FakeClock clock;
  Pacer pacer(1.0, clock);
  EXPECT_EQ(pacer.WaitFor(50000000), 0);  // anchors: stream 50 s = wall 1 s
  EXPECT_TRUE(clock.sleeps.empty());
  clock.now += 2000;                       // 2 ms of decoding
  EXPECT_EQ(pacer.WaitFor(50008333), 0);
  EXPECT_EQ(clock.now, 1008333);
  EXPECT_EQ(pacer.WaitFor(50016667), 0);
  EXPECT_EQ(clock.now, 1016667);
}

TEST(Pacer, SpeedScalesTheWait) {
  for (double speed : {0.5, 2.0, 4.0}) {
    FakeClock clock;
    Pacer pacer(speed, clock);
    pacer.WaitFor(0);
    pacer.WaitFor(1000000);
    EXPECT_EQ(clock.now, 1000000 + std::llround(1e6 / speed)) << speed;
  }
}

TEST(Pacer, SpeedZeroNeverWaits) {
  FakeClock clock;
  Pacer pacer(0.0, clock);
  for (int64_t t = 0; t < 10000000; t += 8333) EXPECT_EQ(pacer.WaitFor(t), 0);
  EXPECT_TRUE(clock.sleeps.empty());
  EXPECT_EQ(clock.now, 1000000);
}

TEST(Pacer, ReportsLatenessAndCatchesUpWithoutSleeping) {
  FakeClock clock;
  Pacer pacer(1.0, clock);
  pacer.WaitFor(0);
  clock.now += 30000;  // a 30 ms stall
  EXPECT_EQ(pacer.WaitFor(10000), 20000);
  EXPECT_EQ(pacer.WaitFor(20000), 10000);
  EXPECT_TRUE(clock.sleeps.empty());
  EXPECT_EQ(pacer.WaitFor(40000), 0);  // back on the original timeline
  EXPECT_EQ(clock.now, 1040000);
  EXPECT_EQ(pacer.max_lateness_us(), 20000);
}

TEST(Pacer, ReanchorsWhenTimeGoesBackwards) {
  FakeClock clock;
  Pacer pacer(1.0, clock);
  pacer.WaitFor(5000000);
  pacer.WaitFor(6000000);
  EXPECT_EQ(clock.now, 2000000);
  pacer.WaitFor(0);  // a new stream
  EXPECT_EQ(clock.now, 2000000);
  pacer.WaitFor(500000);
  EXPECT_EQ(clock.now, 2500000);
}

TEST(Pacer, RejectsNegativeOrNonFiniteSpeed) {
  EXPECT_THROW(Pacer(-1.0), std::invalid_argument);
  EXPECT_THROW(Pacer(std::nan("")), std::invalid_argument);
}

TEST(Pacer, RealClockHoldsTheSchedule) {
  Pacer pacer(1.0);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i <= 30; ++i) pacer.WaitFor(i * 10000);  // 0.3 s at 100 fps
  const double s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NEAR(s, 0.3, 0.006);
}

}  // namespace
}  // namespace bouncefit
