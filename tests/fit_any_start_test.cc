// Any apex seen or heard is a state the fit starts from (the ball at that height,
// at rest vertically); bounce 0 used when seen, never required; several drops; a fit that
// does not match its heights is no answer; the ball's own bounce standard as e at its speed.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "fit/fit_notes.h"
#include "fit/fit_session.h"
#include "model/ball_preset.h"
#include "model/bounce_standard.h"
#include "model/point_mass_model.h"
#include "pipeline/offline_fit.h"
#include "tests/point_mass_truth.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

// Apex heights of the truth drop: [0] the release, [i] rebound i.
std::vector<double> Apexes(const BallPreset& ball, double drop) {
  return testing::PointMassTruth(ball, drop).apex_heights_m;
}

FitSessionConfig PointMassConfig() {
  FitSessionConfig c;
  c.ensemble_members = 1;
  c.safe_drops_m = {};
  c.max_evaluations_final = 300;
  return c;
}

TEST(FitAnyStart, ReleaseNotSeenStartsFromTheFirstApexInView) {
  BallPreset truth = *FindBallPreset("tennis");
  truth.restitution = 0.8;
  truth.restitution_per_mps = 0.02;
  const auto h = Apexes(truth, 1.5);
  ASSERT_GT(h[7], 0.01);
  ASSERT_GE(h.size(), 8u);
  const BallPreset ball = *FindBallPreset("tennis");  // the preset: another e
  PointMassModel model(ball), quick(ball);
  FitSession s(model, &quick, PointMassConfig());
  // Bounces 2.. only: no release, no first rebound.
  s.AddPeak({0, 2, h[2]});
  EXPECT_FALSE(s.CanFit());  // one apex: a start, nothing after it yet
  s.AddPeak({0, 3, h[3]});
  ASSERT_TRUE(s.CanFit());
  EXPECT_EQ(s.start_bounce(), 2);
  EXPECT_DOUBLE_EQ(s.drop_height_m(), h[2]);
  for (int b = 4; b <= 7; ++b) s.AddPeak({0, b, h[b]});
  EXPECT_EQ(s.FittedHeights().size(), 5u);
  const FitUpdate u = s.FinalUpdate();
  EXPECT_EQ(u.start_bounce, 2);
  EXPECT_EQ(u.after_bounce, 7);
  EXPECT_TRUE(u.no_answer.empty()) << u.no_answer;
  EXPECT_LT(u.residual_m, 0.001);
  // The law itself, not just these heights: e at 1 and 4 m/s as the truth's.
  EXPECT_NEAR(FittedRestitutionAt(u.values, 1.0), truth.RestitutionAt(1.0), 0.02);
  EXPECT_NEAR(FittedRestitutionAt(u.values, 4.0), truth.RestitutionAt(4.0), 0.02);
}

TEST(FitAnyStart, TheReleaseIsTheStartWhenSeenAndALaterRunWhenBroken) {
  const BallPreset ball = *FindBallPreset("pingpong");
  const auto h = Apexes(ball, 1.0);
  PointMassModel model(ball), quick(ball);
  FitSession s(model, &quick, PointMassConfig());
  s.AddPeak({0, 1, h[1]});
  s.AddPeak({0, 2, h[2]});
  EXPECT_EQ(s.start_bounce(), 1);
  s.AddPeak({0, 0, h[0]});  // the release, emitted late
  EXPECT_EQ(s.start_bounce(), 0);
  EXPECT_EQ(s.FittedHeights().size(), 2u);
  // A drop seen in two pieces (bounce 3 missed): the longer run is fitted.
  FitSession g(model, &quick, PointMassConfig());
  for (int b : {1, 2, 4, 5, 6, 7}) g.AddPeak({0, b, h[b]});
  EXPECT_EQ(g.start_bounce(), 4);
  EXPECT_EQ(g.FittedHeights().size(), 3u);
  // An apex above the one before it is no rebound of it (picked up and dropped again): it
  // ends a run.
  FitSession r(model, &quick, PointMassConfig());
  for (int b : {0, 1, 2, 3}) r.AddPeak({0, b, h[b]});
  r.AddPeak({0, 4, 0.9});
  EXPECT_EQ(r.start_bounce(), 0);
  EXPECT_EQ(r.FittedHeights().size(), 3u);
  // A revision of the start moves the start's height.
  g.AddPeak({0, 4, h[4] + 0.001});
  EXPECT_DOUBLE_EQ(g.drop_height_m(), h[4] + 0.001);
}

TEST(FitAnyStart, HeightsNoBallMakesAreNoAnswer) {
  const BallPreset ball = *FindBallPreset("tennis");
  PointMassModel model(ball), quick(ball);
  FitSession s(model, &quick, PointMassConfig());
  // Falling heights no restitution law gives: nearly all kept, then a fifth, then nearly all.
  for (auto [b, hm] : std::vector<std::pair<int, double>>{{0, 1.0}, {1, 0.95}, {2, 0.20}, {3, 0.19}, {4, 0.05}})
    s.AddPeak({0, b, hm, 0.002});
  const FitUpdate u = s.FinalUpdate();
  EXPECT_FALSE(u.no_answer.empty()) << "residual " << u.residual_m;
  EXPECT_NE(u.no_answer.find("RMS from the recorded ones, more than"), std::string::npos) << u.no_answer;
}

TEST(FitAnyStart, PeaksCsvDropsStartAnywhere) {
  const auto dir = testing::ScratchDir("fit_any_start_csv");
  const auto path = dir / "peaks.csv";
  std::ofstream(path) << "bounce,t_s,height_m\n"
                         "1,0.50,0.60\n2,1.20,0.40\n3,1.75,0.27\n"   // a drop begun in flight
                         "0,4.00,1.00\n1,4.90,0.62\n2,5.60,0.41\n";  // picked up, dropped again
  const auto drops = ReadPeaksDrops(path);
  ASSERT_EQ(drops.size(), 2u);
  EXPECT_EQ(drops[0].front().bounce, 1);
  EXPECT_EQ(drops[0].size(), 3u);
  EXPECT_EQ(drops[1].front().bounce, 0);
  EXPECT_EQ(ReadDropPeaks(path).size(), 3u);
}

TEST(FitAnyStart, TwoDropsFittedJointlyEachFromItsOwnStart) {
  BallPreset truth = *FindBallPreset("pingpong");
  truth.restitution = 0.85;
  truth.restitution_per_mps = 0.02;
  const auto a = Apexes(truth, 1.2), b = Apexes(truth, 0.7);
  std::vector<std::vector<PeakInput>> drops(2);
  for (int i = 2; i <= 6; ++i) drops[0].push_back({0, i - 1, a[i]});  // numbered from 1: release unseen
  for (int i = 0; i <= 4; ++i) drops[1].push_back({0, i, b[i]});
  FitSetup setup;
  setup.ball = ResolveBallPreset("pingpong");
  setup.model = "point-mass";
  setup.session = PointMassConfig();
  const FitUpdate u = FitDropsOffline(drops, setup, true, [](const FitUpdate&) {});
  EXPECT_TRUE(u.no_answer.empty()) << u.no_answer;
  EXPECT_EQ(u.other_drop_heights_m.size(), 1u);
  EXPECT_EQ(u.recorded_m.size(), 8u);
  EXPECT_LT(u.residual_m, 0.001);
  EXPECT_NEAR(FittedRestitutionAt(u.values, 4.0), truth.RestitutionAt(4.0), 0.02);
}

TEST(BounceStandard, TennisOnConcreteWithDrag) {
  const BallPreset ball = *FindBallPreset("tennis");
  const auto s = BounceStandardOf("tennis");
  ASSERT_TRUE(s);
  const StandardRestitution r = StandardRestitutionOf(*s, ball);
  // Drag-free: sqrt(2 g 2.54) = 7.06 m/s and e = sqrt(1.35 / 2.54) .. sqrt(1.47 / 2.54) = 0.729-0.761;
  // drag slows the fall and shortens the rise.
  EXPECT_NEAR(r.impact_mps, 6.88, 0.02);
  EXPECT_NEAR(r.e_lo, 0.758, 0.005);
  EXPECT_NEAR(r.e_hi, 0.792, 0.005);
  for (const auto& name : {"pingpong", "basketball", "football"}) {
    const auto t = BounceStandardOf(name);
    ASSERT_TRUE(t) << name;
    const StandardRestitution x = StandardRestitutionOf(*t, *FindBallPreset(name));
    EXPECT_GT(x.e_lo, 0.5) << name;
    EXPECT_LT(x.e_hi, 0.97) << name;
  }
  EXPECT_FALSE(BounceStandardOf("airball"));
}

}  // namespace
}  // namespace bouncefit
