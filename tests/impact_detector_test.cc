// The impact detector on rendered sound with known click times: real point-mass drops
// (impact times and speeds from the model), clean and with voices and hum over them.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "detect/impact_detector.h"
#include "model/ball_preset.h"
#include "model/point_mass_drop.h"
#include "synth/synth_audio.h"

namespace bouncefit {
namespace {

struct Drop {
  std::vector<double> times, speeds;
};

Drop PointMassImpacts(const std::string& ball, double height, double start_s) {
  PointMassDropConfig c;
  c.ball = ResolveBallPreset(ball);
  c.drop_height_m = height;
  c.hold_s = start_s;
  c.end_time_s = start_s + 6;
  const PointMassDropResult r = SimulatePointMassDrop(c);
  return {r.impact_times_s, r.impact_speeds_mps};
}

// Truth impacts at or above min_speed each matched (within tol) by one detection; returns
// the largest error, counts misses and detections matching no truth impact at all.
struct Score {
  int missed = 0, invented = 0;
  double max_error_s = 0;
};
Score Compare(const Drop& truth, const std::vector<AudioImpact>& found, double offset_s,
              double min_speed, double tol) {
  Score s;
  std::vector<bool> used(found.size(), false);
  for (size_t k = 0; k < truth.times.size(); ++k) {
    const double t = truth.times[k] + offset_s;
    int best = -1;
    for (size_t i = 0; i < found.size(); ++i)
      if (!used[i] && std::abs(found[i].t_s - t) < tol &&
          (best < 0 || std::abs(found[i].t_s - t) < std::abs(found[best].t_s - t)))
        best = static_cast<int>(i);
    if (best >= 0) {
      used[best] = true;
      s.max_error_s = std::max(s.max_error_s, std::abs(found[best].t_s - t));
    } else if (truth.speeds[k] >= min_speed) {
      ++s.missed;
      ADD_FAILURE() << "missed the impact at " << t << " s, " << truth.speeds[k] << " m/s";
    }
  }
  for (bool u : used) s.invented += !u;
  return s;
}

TEST(ImpactDetector, CleanSoundHearsEveryImpactToATenthOfAMillisecond) {
  for (const std::string ball : {"pingpong", "tennis", "softball"}) {
    const Drop drop = PointMassImpacts(ball, 1.2, 0.4);
    SynthAudioConfig sc;
    sc.seed = 7;
    const auto samples = RenderSynthAudio(sc, 7.0, drop.times, drop.speeds);
    const auto found = DetectImpacts(samples, sc.sample_rate, 0.0);
    const Score s = Compare(drop, found, 0.0, 0.5, 0.005);
    SCOPED_TRACE(ball + ": " + std::to_string(drop.times.size()) + " impacts, " +
                 std::to_string(found.size()) + " found");
    EXPECT_EQ(s.missed, 0);
    EXPECT_EQ(s.invented, 0);
    EXPECT_LT(s.max_error_s, 0.0003);
  }
}

TEST(ImpactDetector, ChatterAndHumInventNothingAndMissNothing) {
  for (uint64_t seed : {1, 2, 3}) {
    const Drop drop = PointMassImpacts("pingpong", 1.0, 0.8);
    SynthAudioConfig sc;
    sc.chatter = true;
    sc.hum = true;
    sc.offset_s = 0.03;
    sc.seed = seed;
    const auto samples = RenderSynthAudio(sc, 7.0, drop.times, drop.speeds);
    const auto found = DetectImpacts(samples, sc.sample_rate, 0.0);
    const Score s = Compare(drop, found, sc.offset_s, 0.5, 0.005);
    SCOPED_TRACE("seed " + std::to_string(seed));
    EXPECT_EQ(s.missed, 0);
    EXPECT_EQ(s.invented, 0);
    EXPECT_LT(s.max_error_s, 0.002);
  }
}

// Soft clicks in white room noise at -44 dBFS (a ball dropped from 0.5 m: most impacts
// slow): each stands only ~10 dB over the noise in the high-passed sound as a whole, more
// in the bands its ring falls in, and a little in every band at once.
TEST(ImpactDetector, SoftClicksInRoomNoiseAreHeardAcrossTheBands) {
  int fast = 0, missed = 0, invented = 0;
  for (uint64_t seed : {1, 2, 3}) {
    const Drop drop = PointMassImpacts("pingpong", 0.5, 0.4);
    SynthAudioConfig sc;
    sc.noise_rms = 0.006;
    sc.seed = seed;
    const auto found =
        DetectImpacts(RenderSynthAudio(sc, 6.0, drop.times, drop.speeds), sc.sample_rate, 0.0);
    for (double v : drop.speeds) fast += v >= 0.5;
    int seed_missed = 0;
    for (size_t k = 0; k < drop.times.size(); ++k) {
      bool heard = false;
      for (const auto& f : found) heard = heard || std::abs(f.t_s - drop.times[k]) < 0.002;
      seed_missed += !heard && drop.speeds[k] >= 0.5;
    }
    missed += seed_missed;
    for (const auto& f : found) {
      bool real = false;
      for (double t : drop.times) real = real || std::abs(f.t_s - t) < 0.002;
      invented += !real;
    }
  }
  EXPECT_GE(fast, 45);
  EXPECT_LE(missed, 0.05 * fast) << missed << " of " << fast << " impacts >= 0.5 m/s missed";
  EXPECT_EQ(invented, 0);
}

TEST(ImpactDetector, VoicesHumAndRoomNoiseAloneAreNotImpacts) {
  for (uint64_t seed : {4, 5, 6, 7}) {
    SynthAudioConfig sc;
    sc.chatter = true;
    sc.hum = true;
    sc.chatter_rms = 0.1;
    sc.seed = seed;
    const auto samples = RenderSynthAudio(sc, 6.0, {}, {});
    EXPECT_TRUE(DetectImpacts(samples, sc.sample_rate, 0.0).empty()) << "seed " << seed;
  }
  SynthAudioConfig quiet;
  quiet.noise_rms = 0.0;  // digital silence
  EXPECT_TRUE(DetectImpacts(RenderSynthAudio(quiet, 2.0, {}, {}), 48000, 0.0).empty());
}

// A phone's AAC encoder spreads a loud transient's quantisation noise over the frame before
// it: a ramp of noise rising ~60 dB over ~23 ms to 10-15 dB under the click, ahead of it (seen on every impact of
// a real phone clip). The impact is the click, once, not the start of the ramp.
TEST(ImpactDetector, AClickBehindAnEncodersPreEchoRampIsHeardOnceAtTheClick) {
  const Drop drop = PointMassImpacts("pingpong", 0.8, 0.5);
  SynthAudioConfig sc;
  sc.noise_rms = 0.00005;  // a quiet room: the ramp's start stands far above it
  auto samples = RenderSynthAudio(sc, 7.0, drop.times, drop.speeds);
  std::mt19937 rng(11);
  std::normal_distribution<double> n01(0, 1);
  const int ramp = 1024;  // one AAC frame at 44.1 kHz
  for (size_t k = 0; k < drop.times.size(); ++k) {
    const double click = sc.click_at_1mps * std::pow(drop.speeds[k], sc.click_exponent);
    const auto at = static_cast<int64_t>(std::lround(drop.times[k] * sc.sample_rate));
    for (int i = 0; i < ramp; ++i) {
      const int64_t s = at - ramp + i;
      if (s < 0 || s >= static_cast<int64_t>(samples.size())) continue;
      // Rising as the window's first half, on a dB scale: -70 dB to -12 dB of the click's
      // peak (the real clip's ramps end 10-15 dB under it, rising ~3 dB per ms).
      const double w = std::sin(0.5 * std::numbers::pi * i / ramp);
      samples[s] += static_cast<float>(click * std::pow(10.0, (-70 + 58 * w) / 20) * n01(rng));
    }
  }
  const auto found = DetectImpacts(samples, sc.sample_rate, 0.0);
  const Score s = Compare(drop, found, 0.0, 0.5, 0.03);
  EXPECT_EQ(s.missed, 0);
  EXPECT_EQ(s.invented, 0);
  // At the click (within 2 ms: the ramp ends only 12 dB under it), not 23 ms early at the
  // ramp's start.
  EXPECT_LT(s.max_error_s, 0.002);
}

TEST(ImpactDetector, ChunkedStreamGivesTheSameImpactsAsOneBlock) {
  const Drop drop = PointMassImpacts("tennis", 0.8, 0.3);
  SynthAudioConfig sc;
  sc.sample_rate = 48000;
  sc.hum = true;
  const auto samples = RenderSynthAudio(sc, 4.0, drop.times, drop.speeds);
  const auto whole = DetectImpacts(samples, sc.sample_rate, 10.0);
  ImpactDetector d({}, sc.sample_rate);
  std::vector<AudioImpact> chunked;
  for (size_t at = 0; at < samples.size(); at += 1001) {
    const size_t n = std::min<size_t>(1001, samples.size() - at);
    for (const auto& i : d.Push(10.0 + static_cast<double>(at) / sc.sample_rate, &samples[at], n))
      chunked.push_back(i);
  }
  for (const auto& i : d.Finish()) chunked.push_back(i);
  ASSERT_EQ(whole.size(), chunked.size());
  ASSERT_FALSE(whole.empty());
  for (size_t k = 0; k < whole.size(); ++k) {
    EXPECT_NEAR(whole[k].t_s, chunked[k].t_s, 1e-9);
    EXPECT_GT(whole[k].confidence, 0.0);
  }
  EXPECT_NEAR(whole.front().t_s, 10.0 + drop.times.front(), 3e-4);
}

TEST(ImpactDetector, LouderForFasterImpacts) {
  const Drop drop = PointMassImpacts("pingpong", 1.0, 0.2);
  SynthAudioConfig sc;
  const auto found = DetectImpacts(RenderSynthAudio(sc, 5.0, drop.times, drop.speeds),
                                   sc.sample_rate, 0.0);
  ASSERT_GE(found.size(), 4u);
  EXPECT_GT(found[0].strength, found[3].strength);
}

TEST(ImpactDetector, RejectsBadConfigWithOneLine) {
  ImpactDetectorConfig c;
  c.floor_percentile = 2;
  EXPECT_THROW(ImpactDetector(c, 44100), std::invalid_argument);
  EXPECT_THROW(ImpactDetector({}, 100), std::invalid_argument);
}

}  // namespace
}  // namespace bouncefit
