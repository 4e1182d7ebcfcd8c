#include "detect/capture_clock.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace bouncefit {
namespace {

// Stamps of a 240 fps capture on a 1/60000 s tick, frames [from, to) stamped `slow` periods apart.
std::vector<int64_t> SlowMotionStamps(int frames, int from, int to, int slow) {
  std::vector<int64_t> out;
  int64_t ticks = 0;
  for (int i = 0; i < frames; ++i) {
    if (i > 0) ticks += (i - 1 >= from && i - 1 < to ? slow : 1) * 250;
    out.push_back(ticks * 1000000 / 60000);
  }
  return out;
}

TEST(CaptureClock, SlowMotionShowsInARunOfSlowedStepsAndIsReadOnePeriodAPicture) {
  const auto stamps = SlowMotionStamps(600, 100, 400, 8);
  // Not known to be slow motion: the stamps as they are, the period and the run found.
  CaptureClock first;
  for (size_t i = 0; i < stamps.size(); ++i) {
    EXPECT_EQ(first.Add(stamps[i]), stamps[i]);
    EXPECT_EQ(first.shows_slow_motion(), i >= 104) << i;
  }
  EXPECT_NEAR(first.capture_period_s(), 1.0 / 240, 1e-6);
  EXPECT_EQ(first.slowed_steps(), 300);
  EXPECT_EQ(first.longest_slowed_run(), 300);
  // Known from the start: every picture one period after the one before.
  CaptureClockConfig known;
  known.known_period_s = CapturePeriodOfStamps(stamps, 4300) * 1e-6;
  known.constant_capture = true;
  CaptureClock clock(known);
  for (size_t i = 0; i < stamps.size(); ++i)
    EXPECT_NEAR(static_cast<double>(clock.Add(stamps[i])), i * 1e6 / 240, 1.0) << i;
  EXPECT_NEAR(clock.max_slowdown(), 8, 0.01);
  EXPECT_NEAR(clock.slowed_real_s(), 300.0 / 240, 1e-3);
  EXPECT_NEAR(clock.slowed_stamp_s(), 300.0 * 8 / 240, 1e-3);
}

TEST(CaptureClock, APictureDroppedNowAndThenIsNoSlowMotion) {
  CaptureClock clock;
  int64_t t = 0;
  for (int i = 0; i < 300; ++i) {
    EXPECT_EQ(clock.Add(t), t);
    t += (i % 50 == 49 ? 2 : 1) * 4167;
  }
  EXPECT_EQ(clock.slowed_steps(), 5);
  EXPECT_FALSE(clock.shows_slow_motion());
}

TEST(CaptureClock, PicturesLostOnTheWayAreNoSlowMotion) {
  // 120 fps boxes over a lossy network: runs of five lost, the index says so.
  CaptureClock clock;
  int64_t index = 0;
  for (int i = 0; i < 300; ++i) {
    const int64_t t = index * 8333;
    EXPECT_EQ(clock.Add(t, index), t);
    index += (i / 10) % 2 ? 6 : 1;
  }
  EXPECT_EQ(clock.slowed_steps(), 0);
  EXPECT_FALSE(clock.shows_slow_motion());
  // Known to be slow motion: the lost pictures are periods too.
  CaptureClockConfig known;
  known.known_period_s = 1.0 / 240;
  known.constant_capture = true;
  CaptureClock slowed(known);
  slowed.Add(0, 0);
  slowed.Add(33333, 1);
  EXPECT_NEAR(static_cast<double>(slowed.Add(66667, 4)), 4 * 1e6 / 240, 1.0);
}

TEST(CaptureClock, AContainersCoarseTickStillShowsTheCapturePeriod) {
  // 240 fps on a 1/600 s tick: steps of 3.3 and 5 ms in turn, 33.3 ms where slowed 8x.
  CaptureClock clock;
  double file_s = 0;
  for (int i = 0; i < 500; ++i) {
    if (i > 0) file_s += (i - 1 >= 100 && i - 1 < 300 ? 8.0 : 1.0) / 240;
    clock.Add(std::llround(std::round(file_s * 600) / 600 * 1e6));
  }
  EXPECT_NEAR(clock.capture_period_s(), 1.0 / 240, 2e-5);
  EXPECT_EQ(clock.slowed_steps(), 200);
  EXPECT_TRUE(clock.shows_slow_motion());
}

// A phone's slow-motion file: 240 fps stamped on a 1/600 s tick half a tick early, the first
// picture at 0 (steps 2, 2, 3, 2, 3 ... ticks: the first four average 3.75 ms, not 4.17), a
// ramp over 0.2 s of real time into 8x slowed, and back.
std::vector<int64_t> PhoneSlowMotionStamps() {
  std::vector<int64_t> out;
  double file_s = 0;
  for (int i = 0; i < 700; ++i) {
    const double real = (i - 1) / 240.0;
    const double edge = std::min(real - 0.4, 2.2 - real);
    if (i > 0) file_s += (edge < 0 ? 1.0 : 1 + 7 * std::min(1.0, edge / 0.2)) / 240;
    out.push_back(std::max<int64_t>(0, static_cast<int64_t>(std::floor(file_s * 600 - 0.5))) * 1000000 / 600);
  }
  return out;
}

TEST(CaptureClock, APhonesSlowMotionOnA600thTickFromAnUnevenStartIsReadAt240) {
  const auto stamps = PhoneSlowMotionStamps();
  CaptureClock clock;
  for (int64_t s : stamps) clock.Add(s);
  EXPECT_NEAR(clock.capture_period_s(), 1.0 / 240, 2e-5);
  EXPECT_TRUE(clock.shows_slow_motion());
  EXPECT_NEAR(CapturePeriodOfStamps(stamps, clock.capture_period_s() * 1e6), 1e6 / 240, 2.0);
  // From the period the stamps' first steps show (3.75 ms) too.
  EXPECT_NEAR(CapturePeriodOfStamps(stamps, 3750), 1e6 / 240, 2.0);
}

TEST(CaptureClock, ThePeriodOfStampsOnACoarseTickThroughARamp) {
  // 240 fps on a 1 ms tick (4, 4, 4, 4, 4, 5 ms), then a ramp: steps 1.1, 1.2, 1.3 ... periods.
  std::vector<int64_t> stamps;
  double file_s = 0;
  for (int i = 0; i < 200; ++i) {
    if (i > 0) file_s += (i > 150 ? 1 + 0.1 * (i - 150) : 1.0) / 240;
    stamps.push_back(std::llround(std::round(file_s * 1000) / 1000 * 1e6));
  }
  EXPECT_NEAR(CapturePeriodOfStamps(stamps, 4300), 1e6 / 240, 1.0);
  // Too few steps of one period in a row: the rough period.
  EXPECT_EQ(CapturePeriodOfStamps({0, 4000, 9000, 13000}, 4300), 4300);
}

TEST(CaptureClock, AWanderingOrdinaryRateIsReadAsStamped) {
  CaptureClock clock;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> period(1 / 30.0, 1 / 26.0);
  int64_t t = 1000;
  for (int i = 0; i < 200; ++i) {
    EXPECT_EQ(clock.Add(t), t);
    t += std::llround(period(rng) * 1e6);
    if (i == 50) t += 2 * 33333;  // two frames dropped: a longer step, still real time
  }
  EXPECT_EQ(clock.capture_period_s(), 0);
  EXPECT_EQ(clock.slowed_steps(), 0);
}

TEST(CaptureClock, AConstantRateIsReadAsStamped) {
  CaptureClock clock;
  for (int i = 0; i < 100; ++i) EXPECT_EQ(clock.Add(i * 4167), i * 4167);
  EXPECT_NEAR(clock.capture_period_s(), 0.004167, 1e-6);
  EXPECT_EQ(clock.slowed_steps(), 0);
}

TEST(CaptureClock, RepeatedOrEarlierStampsChangeNothing) {
  CaptureClock clock;
  clock.Add(0);
  clock.Add(4167);
  EXPECT_EQ(clock.Add(4167), 4167);
  EXPECT_EQ(clock.Add(100), 4167);
  EXPECT_EQ(clock.last_taken(), 4167);
}

}  // namespace
}  // namespace bouncefit
