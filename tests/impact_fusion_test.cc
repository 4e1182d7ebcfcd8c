// Fusing heard and seen impacts, on real point-mass drops (times, speeds and apex heights
// from the model): the offset, the heard-only bounce train, flight-time heights, and sound
// that disagrees with the picture.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <algorithm>
#include <random>

#include "detect/heard_peaks.h"
#include "detect/impact_fusion.h"
#include "model/ball_preset.h"
#include "model/point_mass_drop.h"

namespace bouncefit {
namespace {

PointMassDropResult Drop(const std::string& ball, double height) {
  PointMassDropConfig c;
  c.ball = ResolveBallPreset(ball);
  c.drop_height_m = height;
  c.hold_s = 0.5;
  c.end_time_s = 8;
  c.min_apex_height_m = 0.001;
  return SimulatePointMassDrop(c);
}

double DragPerM(const BallPreset& b) {
  const double area = std::numbers::pi * b.diameter_m * b.diameter_m / 4;
  return 0.5 * 1.2 * b.drag_coefficient * area / b.mass_kg;
}

// The fusion's config for a ball: its air drag, as `run` gives it.
ImpactFusionConfig ConfigFor(const std::string& ball) {
  ImpactFusionConfig c;
  c.drag_per_m = DragPerM(ResolveBallPreset(ball));
  return c;
}

std::vector<AudioImpact> Heard(const std::vector<double>& times, double offset) {
  std::vector<AudioImpact> out;
  for (double t : times) out.push_back({t + offset, 0.1, 30, 1});
  return out;
}

TEST(FlightTimeHeight, VacuumFormulaAndDragAgainstThePointMassModel) {
  EXPECT_NEAR(FlightTimeHeight(0.9, 9.81, 0), 9.81 * 0.81 / 8, 1e-12);
  for (const std::string ball : {"pingpong", "tennis", "wiffle"}) {
    const PointMassDropResult r = Drop(ball, 1.5);
    const double k = DragPerM(ResolveBallPreset(ball));
    int checked = 0;
    for (size_t i = 0; i + 1 < r.impact_times_s.size(); ++i) {
      const double truth = r.apex_heights_m[i + 1];
      if (truth < 0.02) break;
      const double h = FlightTimeHeight(r.impact_times_s[i + 1] - r.impact_times_s[i], 9.81, k);
      EXPECT_NEAR(h, truth, 0.005 * truth) << ball << " bounce " << i + 1;
      ++checked;
    }
    EXPECT_GE(checked, 3) << ball;
  }
}

TEST(ImpactFusion, OffsetPairsHeardOnlyTrainAndStraySoundsRejected) {
  const PointMassDropResult r = Drop("pingpong", 1.0);
  ASSERT_GE(r.impact_times_s.size(), 12u);
  // Seen: the first 6 impacts, each off by up to a third of a 30 fps frame.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.011, 0.011);
  std::vector<double> seen;
  for (int i = 0; i < 6; ++i) seen.push_back(r.impact_times_s[i] + jitter(rng));
  // Heard: every impact, 30 ms late, plus a door slam before the drop and a cough after.
  auto heard = Heard(r.impact_times_s, 0.03);
  heard.push_back({0.2, 0.3, 30, 1});
  heard.push_back({r.impact_times_s.back() + 0.7, 0.3, 30, 1});
  const ImpactFusionConfig c = ConfigFor("pingpong");
  const FusionResult f = FuseImpacts(heard, seen, r.impact_times_s.back() + 1, c);
  ASSERT_TRUE(f.sound_used) << f.verdict;
  EXPECT_NEAR(f.offset_s, 0.03, 0.011);
  EXPECT_EQ(f.matched, 6);
  EXPECT_EQ(f.rejected_sounds, 2);
  ASSERT_EQ(f.impacts.size(), r.impact_times_s.size());
  for (size_t i = 0; i < f.impacts.size(); ++i) {
    EXPECT_EQ(f.impacts[i].source, i < 6 ? ImpactSource::kBoth : ImpactSource::kAudio);
    EXPECT_NEAR(f.impacts[i].t_s, r.impact_times_s[i], 0.011);
  }
  ASSERT_EQ(f.flights.size(), r.impact_times_s.size() - 1);
  for (const auto& fl : f.flights) {
    const double truth = r.apex_heights_m[fl.from + 1];
    EXPECT_NEAR(fl.height_m, truth, 0.005 * truth + 0.0002) << "bounce " << fl.from + 1;
    EXPECT_EQ(fl.heard_only, fl.from >= 5);
  }
}

// The tracker locked on after three bounces (the football clip): those three impacts were
// heard, and the first impact it saw, timed a frame late, is the fourth heard one.
// A 24 fps picture: one impact seen twice (a small arc split by a noisy sample, a frame
// apart) and one seen a frame late, both beside heard impacts. The duplicate is dropped and
// the late one pairs, so every flight between heard impacts gives a height.
TEST(ImpactFusion, ASeenImpactNearAHeardOneIsThatImpact) {
  const PointMassDropResult r = Drop("pingpong", 0.6);
  ASSERT_GE(r.impact_times_s.size(), 16u);
  const auto& t = r.impact_times_s;
  std::vector<double> seen(t.begin(), t.begin() + 14);
  // Impact 12 a frame late: beyond a quarter of its flights (0.16 s), within a frame.
  ASSERT_LT(0.25 * std::min(t[12] - t[11], t[13] - t[12]), 0.042);
  seen[12] += 0.042;
  seen.push_back(t[4] - 0.024);  // the arc before impact 4 split near its end
  std::sort(seen.begin(), seen.end());
  ImpactFusionConfig c = ConfigFor("pingpong");
  c.frame_period_s = 1 / 24.0;
  const FusionResult f = FuseImpacts(Heard(t, -0.04), seen, t.back() + 1, c);
  ASSERT_TRUE(f.sound_used) << f.verdict;
  ASSERT_EQ(f.merged_seen.size(), 1u);
  EXPECT_NEAR(f.merged_seen[0], t[4] - 0.024, 1e-9);
  ASSERT_EQ(f.impacts.size(), t.size());
  for (size_t i = 0; i < f.impacts.size(); ++i) {
    EXPECT_NEAR(f.impacts[i].t_s, t[i], 1e-6) << i;
    EXPECT_EQ(f.impacts[i].source, i < 14 ? ImpactSource::kBoth : ImpactSource::kAudio) << i;
  }
  EXPECT_EQ(f.flights.size(), t.size() - 1);
  // Without the frame period a quarter flight is the limit: the late one stays seen only.
  c.frame_period_s = 0;
  const FusionResult narrow = FuseImpacts(Heard(t, -0.04), seen, t.back() + 1, c);
  int video = 0;
  for (const auto& i : narrow.impacts) video += i.source == ImpactSource::kVideo;
  EXPECT_EQ(video, 1);
}

// A 20 fps picture times each impact to some 15 ms: the pairs' differences scatter over 31 ms
// here, and they pair at one offset only between them, not at any one difference.
TEST(ImpactFusion, PairsWhoseDifferencesScatterPairAtAnOffsetBetweenThem) {
  const PointMassDropResult r = Drop("tennis", 1.0);
  ASSERT_GE(r.impact_times_s.size(), 5u);
  const std::vector<double> t(r.impact_times_s.begin(), r.impact_times_s.begin() + 5);
  const double scatter[] = {-0.0122, 0.0151, -0.0061, 0.0191, 0};  // seen - heard, s
  std::vector<double> seen;
  for (size_t i = 0; i < t.size(); ++i) seen.push_back(t[i] + scatter[i]);
  std::vector<AudioImpact> heard = Heard(t, 0.010);
  heard.pop_back();  // the last one too quiet to hear
  const FusionResult f = FuseImpacts(heard, seen, t.back() + 1, ConfigFor("tennis"));
  ASSERT_TRUE(f.sound_used) << f.verdict;
  EXPECT_EQ(f.matched, 4) << f.verdict;
  EXPECT_NEAR(f.offset_s, 0.010, 0.02);
}

TEST(ImpactFusion, BouncesHeardBeforeThePictureFoundTheBallAreKept) {
  const PointMassDropResult r = Drop("tennis", 1.5);
  ASSERT_GE(r.impact_times_s.size(), 9u);
  std::vector<double> seen;
  for (int i = 3; i < 9; ++i) seen.push_back(r.impact_times_s[i] + (i == 3 ? 0.05 : 0.004));
  // Heard: every impact 13 ms late, a door slam and a voice's click during the hold.
  auto heard = Heard(r.impact_times_s, 0.013);
  heard.push_back({r.apex_times_s[0] - 0.3, 0.3, 30, 1});
  heard.push_back({r.apex_times_s[0] + 0.1, 0.2, 30, 1});
  const ImpactFusionConfig c = ConfigFor("tennis");
  const FusionResult f = FuseImpacts(heard, seen, r.impact_times_s.back() + 1, c);
  ASSERT_TRUE(f.sound_used) << f.verdict;
  EXPECT_EQ(f.rejected_sounds, 2);
  ASSERT_EQ(f.impacts.size(), r.impact_times_s.size());
  for (size_t i = 0; i < f.impacts.size(); ++i) {
    EXPECT_EQ(f.impacts[i].source, i < 3 ? ImpactSource::kAudio
                                   : i < 9 ? ImpactSource::kBoth
                                           : ImpactSource::kAudio) << "impact " << i;
    EXPECT_NEAR(f.impacts[i].t_s, r.impact_times_s[i], 0.005) << "impact " << i;
  }
  EXPECT_NEAR(f.impacts[3].video_t_s, seen[0], 1e-12);  // the late-timed seen impact, merged
  for (const auto& fl : f.flights) {
    const double truth = r.apex_heights_m[fl.from + 1];
    EXPECT_NEAR(fl.height_m, truth, 0.005 * truth + 0.0002) << "bounce " << fl.from + 1;
  }
}

// The same, when the picture also misses the impact right after its first seen one (a
// smeared frame at the floor): the bounce train is read back in time from heard flights, the
// heard-only impact among them as good as one also seen.
TEST(ImpactFusion, BouncesHeardBeforeThePictureFoundTheBallAreKeptWhenItMissesTheNext) {
  const PointMassDropResult r = Drop("tennis", 1.5);
  ASSERT_GE(r.impact_times_s.size(), 9u);
  std::vector<double> seen;
  for (int i = 3; i < 9; ++i)
    if (i != 4) seen.push_back(r.impact_times_s[i] + 0.004);
  const auto heard = Heard(r.impact_times_s, 0.013);
  const ImpactFusionConfig c = ConfigFor("tennis");
  const FusionResult f = FuseImpacts(heard, seen, r.impact_times_s.back() + 1, c);
  ASSERT_TRUE(f.sound_used) << f.verdict;
  EXPECT_EQ(f.rejected_sounds, 0);
  ASSERT_EQ(f.impacts.size(), r.impact_times_s.size());
  for (size_t i = 0; i < f.impacts.size(); ++i) {
    const bool seen_too = i >= 3 && i < 9 && i != 4;
    EXPECT_EQ(f.impacts[i].source, seen_too ? ImpactSource::kBoth : ImpactSource::kAudio) << "impact " << i;
    EXPECT_NEAR(f.impacts[i].t_s, r.impact_times_s[i], 0.005) << "impact " << i;
  }
}

// A gym: every impact's click comes back off the walls 60 ms later, a tenth as loud. The echoes
// are the impacts heard again: the picture pairs with the clicks (the sound 150 ms behind it),
// not with their echoes, and the echoes count neither as impacts nor against the sound; the
// bounces heard before the picture found the ball are read back from the clicks alone.
TEST(ImpactFusion, EchoesOffTheWallsAreTheImpactsHeardAgain) {
  const PointMassDropResult r = Drop("basketball", 1.2);
  ASSERT_GE(r.impact_times_s.size(), 8u);
  std::vector<double> seen;
  for (int i = 2; i < 8; ++i) seen.push_back(r.impact_times_s[i] + 0.004);
  std::vector<AudioImpact> heard;
  for (double t : r.impact_times_s) {
    heard.push_back({t + 0.15, 0.3, 40, 1});
    heard.push_back({t + 0.21, 0.03, 20, 1});
  }
  const FusionResult f = FuseImpacts(heard, seen, r.impact_times_s.back() + 1, ConfigFor("basketball"));
  ASSERT_TRUE(f.sound_used) << f.verdict;
  EXPECT_NEAR(f.offset_s, 0.15, 0.015) << f.verdict;
  EXPECT_EQ(f.matched, 6) << f.verdict;
  EXPECT_EQ(f.rejected_sounds, static_cast<int>(r.impact_times_s.size())) << "the echoes";
  ASSERT_EQ(f.impacts.size(), r.impact_times_s.size());
  for (size_t i = 0; i < f.impacts.size(); ++i)
    EXPECT_NEAR(f.impacts[i].t_s, r.impact_times_s[i], 0.005) << "impact " << i;
}

// The picture's last impact unheard (quiet), a stray click in the flight before it: the picture
// watched the ball up to that impact, so the click is no bounce of the train heard after it.
TEST(ImpactFusion, AClickBetweenThePicturesLastImpactsIsNoBounce) {
  const PointMassDropResult r = Drop("tennis", 1.2);
  ASSERT_GE(r.impact_times_s.size(), 6u);
  const std::vector<double> seen(r.impact_times_s.begin(), r.impact_times_s.begin() + 6);
  auto heard = Heard(std::vector<double>(seen.begin(), seen.begin() + 5), 0.013);
  heard.push_back({seen[4] + 0.5 * (seen[5] - seen[4]) + 0.013, 0.05, 20, 1});
  const FusionResult f = FuseImpacts(heard, seen, seen.back() + 1, ConfigFor("tennis"));
  ASSERT_TRUE(f.sound_used) << f.verdict;
  ASSERT_EQ(f.impacts.size(), seen.size());
  EXPECT_EQ(f.impacts.back().source, ImpactSource::kVideo);
  EXPECT_EQ(f.rejected_sounds, 1);
}

TEST(ImpactFusion, SoundThatDisagreesWithThePictureIsNotUsed) {
  const PointMassDropResult r = Drop("tennis", 1.2);
  std::vector<double> seen(r.impact_times_s.begin(), r.impact_times_s.begin() + 5);
  // A slow-motion file: the picture slowed 4x, the sound in real time.
  std::vector<double> slow;
  for (double t : seen) slow.push_back(4 * t);
  const FusionResult f = FuseImpacts(Heard(r.impact_times_s, 0.0), slow, 20, {});
  EXPECT_FALSE(f.sound_used);
  EXPECT_NE(f.verdict.find("does not agree"), std::string::npos) << f.verdict;
  for (const auto& i : f.impacts) EXPECT_EQ(i.source, ImpactSource::kVideo);
  EXPECT_TRUE(f.flights.empty());
  // Random knocks, nothing to do with the ball.
  std::vector<AudioImpact> knocks;
  for (double t = 0.13; t < 5; t += 0.37) knocks.push_back({t, 0.1, 20, 0.8});
  const FusionResult g = FuseImpacts(knocks, seen, 5, {});
  EXPECT_FALSE(g.sound_used) << g.verdict;
  // No sound at all, and nothing seen.
  EXPECT_FALSE(FuseImpacts({}, seen, 5, {}).sound_used);
  EXPECT_FALSE(FuseImpacts(Heard(seen, 0), {}, 5, {}).sound_used);
}

TEST(ImpactFusion, NothingSeenListsOnlyAHeardBounceTrain) {
  const PointMassDropResult r = Drop("tennis", 1.0);
  auto heard = Heard(r.impact_times_s, 0.0);
  heard.push_back({0.6, 0.2, 30, 1});                          // a knock during the fall
  heard.push_back({r.impact_times_s[2] + 0.004, 0.2, 30, 1});  // an echo
  const FusionResult f = FuseImpacts(heard, {}, 8, {});
  EXPECT_FALSE(f.sound_used);
  EXPECT_TRUE(f.heard_train_only) << f.verdict;
  ASSERT_EQ(f.impacts.size(), r.impact_times_s.size());
  for (size_t i = 0; i < f.impacts.size(); ++i) {
    EXPECT_EQ(f.impacts[i].source, ImpactSource::kAudio);
    EXPECT_DOUBLE_EQ(f.impacts[i].t_s, r.impact_times_s[i]);
  }
  EXPECT_EQ(f.rejected_sounds, 2);
  // Knocks at random times make no train.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> when(0, 10);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<AudioImpact> knocks;
    for (int i = 0; i < 8; ++i) knocks.push_back({when(rng), 0.1, 25, 0.9});
    std::sort(knocks.begin(), knocks.end(), [](auto& a, auto& b) { return a.t_s < b.t_s; });
    const FusionResult g = FuseImpacts(knocks, {}, 10, {});
    EXPECT_TRUE(g.impacts.empty()) << "trial " << trial << ": " << g.verdict;
  }
}

// A 30 fps picture that split one arc in two (an extra apex at a frame on the arc's way
// up): the heard impacts bound the arc, so only the apex nearest its heard apex is the bounce.
TEST(HeardPeaks, ASplitArcKeepsTheApexNearestTheHeardOne) {
  const PointMassDropResult r = Drop("pingpong", 1.0);
  ASSERT_GE(r.impact_times_s.size(), 6u);
  std::vector<double> seen(r.impact_times_s.begin(), r.impact_times_s.begin() + 6);
  const ImpactFusionConfig c = ConfigFor("pingpong");
  const FusionResult f = FuseImpacts(Heard(seen, 0.03), seen, seen.back() + 0.5, c);
  ASSERT_TRUE(f.sound_used) << f.verdict;
  ASSERT_EQ(f.flights.size(), 5u);
  // Apexes seen: the release (before any heard impact), the true apexes of bounces 1-5 a
  // frame (33 ms) off, and a spurious one 70 ms before bounce 3's apex.
  std::vector<double> apex = {r.apex_times_s[0]};
  for (int b = 1; b <= 5; ++b) apex.push_back(r.apex_times_s[b] + (b % 2 ? 0.033 : -0.033));
  apex.insert(apex.begin() + 3, r.apex_times_s[3] - 0.07);
  const std::vector<ApexOnArc> on = PlaceApexesOnHeardArcs(apex, f);
  ASSERT_EQ(on.size(), apex.size());
  EXPECT_EQ(on[0].flight, -1);
  for (size_t p = 1; p < on.size(); ++p) {
    const int bounce = p <= 3 ? static_cast<int>(p) : static_cast<int>(p) - 1;
    EXPECT_EQ(on[p].flight, bounce - 1) << "apex " << p;
    EXPECT_EQ(on[p].duplicate, p == 3) << "apex " << p;
    EXPECT_NEAR(f.flights[on[p].flight].height_m, r.apex_heights_m[bounce],
                0.005 * r.apex_heights_m[bounce]);
  }
}

}  // namespace
}  // namespace bouncefit
