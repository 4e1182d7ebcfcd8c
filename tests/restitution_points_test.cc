// fit/restitution_points.h: restitution impact by impact from consecutive apexes, and whether
// the bounces and the drops of one ball tell one story. Heights from synth's point mass
// (model/point_mass_drop.h) with a known e(v) and drag.
#include "fit/restitution_points.h"

#include <gtest/gtest.h>

#include <cmath>

#include "model/ball_preset.h"
#include "model/point_mass_drop.h"

namespace bouncefit {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The release and the rebound apexes of a point-mass drop, down to 1 cm.
std::vector<double> Apexes(BallPreset ball, double e0, double k, double drop_m, bool drag = true) {
  ball.restitution = e0;
  ball.restitution_per_mps = k;
  PointMassDropConfig c;
  c.ball = ball;
  c.drop_height_m = drop_m;
  c.drag = drag;
  c.end_time_s = 20;
  std::vector<double> out;
  for (double h : SimulatePointMassDrop(c).apex_heights_m)
    if (h >= 0.01) out.push_back(h);
  return out;
}

double DragPerM(const BallPreset& ball) {
  return 1.2 * ball.drag_coefficient * kPi * ball.diameter_m * ball.diameter_m / 4 / (2 * ball.mass_kg);
}

std::vector<RestitutionPoint> Points(const std::vector<double>& apexes, const BallPreset& ball, int drop) {
  return MeasureRestitution(apexes, std::vector<double>(apexes.size(), 0.001), DragPerM(ball), drop);
}

// Each pair of apexes gives the e(v) the drop was made with, at the impact speed with drag,
// for a light ball (ping-pong: drag matters) and a heavy one.
TEST(RestitutionPoints, EachImpactGivesTheLawAtItsSpeed) {
  for (const char* name : {"pingpong", "basketball"}) {
    const BallPreset ball = ResolveBallPreset(name, 0, 0);
    const std::vector<double> h = Apexes(ball, 0.9, 0.03, 1.5);
    const auto points = Points(h, ball, 0);
    ASSERT_GE(points.size(), 5u) << name;
    for (const auto& p : points) {
      EXPECT_NEAR(p.e, 0.9 - 0.03 * p.speed_mps, 0.002) << name << " bounce " << p.bounce << " at " << p.speed_mps;
      EXPECT_GT(p.sigma, 0) << name;
    }
    EXPECT_NEAR(points.front().speed_mps, std::sqrt(2 * 9.81 * 1.5), name == std::string("pingpong") ? 1.0 : 0.2);
  }
}

// Without drag, e = sqrt(h_i / h_{i-1}) and the speed is sqrt(2 g h).
TEST(RestitutionPoints, WithoutDragTheRatioOfHeights) {
  const auto points = MeasureRestitution({1.0, 0.64, 0.4096}, {}, 0, 0, 3);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_NEAR(points[0].e, 0.8, 1e-9);
  EXPECT_NEAR(points[0].speed_mps, std::sqrt(2 * 9.81), 1e-9);
  EXPECT_EQ(points[0].bounce, 4);  // numbered from the start's bounce 3
  EXPECT_EQ(points[1].bounce, 5);
}

// Three drops of one ball from three heights: one curve, the drops agree, e0 and k are the
// law's, and each drop's e at the reference speed is the law's there.
TEST(RestitutionPoints, DropsOfOneBallAgree) {
  const BallPreset ball = ResolveBallPreset("tennis", 0, 0);
  std::vector<RestitutionPoint> all;
  int drop = 0;
  for (double h : {0.8, 1.2, 1.8}) {
    const auto p = Points(Apexes(ball, 0.82, 0.012, h), ball, drop++);
    all.insert(all.end(), p.begin(), p.end());
  }
  RestitutionConsistencyOptions o;
  o.reference_mps = 3;
  const RestitutionConsistency c = CheckRestitution(all, o);
  EXPECT_EQ(c.drops, 3);
  EXPECT_TRUE(c.drops_agree) << DropsDisagreement(c);
  EXPECT_NEAR(c.e0, 0.82, 0.005);
  EXPECT_NEAR(c.k, 0.012, 0.003);
  ASSERT_EQ(c.drop_e.size(), 3u);
  for (size_t d = 0; d < 3; ++d) EXPECT_NEAR(c.drop_e[d], 0.82 - 0.012 * 3, 0.01) << "drop " << d + 1;
  EXPECT_TRUE(c.suspect.empty());
  // The scatter is at least what real impacts add: the sigma of e0 is not the heights' alone.
  EXPECT_GE(c.scatter, o.min_scatter);
  EXPECT_GT(c.sigma_e0, 0.002);
  EXPECT_LT(c.sigma_e0, 0.02);
}

// One drop whose ball kept less (0.72 where the others keep 0.84): the drops disagree, and
// the reason names every drop's e.
TEST(RestitutionPoints, ADropOfAnotherRestitutionDisagrees) {
  const BallPreset ball = ResolveBallPreset("pingpong", 0, 0);
  std::vector<RestitutionPoint> all;
  int drop = 0;
  for (double e0 : {0.72, 0.84, 0.84}) {
    const auto p = Points(Apexes(ball, e0, 0.005, 1.0), ball, drop++);
    all.insert(all.end(), p.begin(), p.end());
  }
  const RestitutionConsistency c = CheckRestitution(all);
  EXPECT_FALSE(c.drops_agree);
  ASSERT_EQ(c.drop_e.size(), 3u);
  EXPECT_LT(c.drop_e[0], c.drop_e[1] - 0.08);
  const std::string why = DropsDisagreement(c);
  for (const char* d : {"drop 1", "drop 2", "drop 3"}) EXPECT_NE(why.find(d), std::string::npos) << why;
}

// Two drops a hair apart (0.01 in e, as two real drops of one ball differ): they agree.
TEST(RestitutionPoints, DropsWithinWhatImpactsScatterAgree) {
  const BallPreset ball = ResolveBallPreset("pingpong", 0, 0);
  std::vector<RestitutionPoint> all;
  int drop = 0;
  for (double e0 : {0.88, 0.89}) {
    const auto p = Points(Apexes(ball, e0, 0.01, 0.6), ball, drop++);
    all.insert(all.end(), p.begin(), p.end());
  }
  EXPECT_TRUE(CheckRestitution(all).drops_agree) << DropsDisagreement(CheckRestitution(all));
}

// An apex higher than the one before allows (e above 1) and one far off the drop's line are
// named, with the bounce.
TEST(RestitutionPoints, BouncesToDoubtAreNamed) {
  const BallPreset ball = ResolveBallPreset("tennis", 0, 0);
  std::vector<double> h = Apexes(ball, 0.8, 0.01, 1.2, false);
  ASSERT_GE(h.size(), 7u);
  h[5] = h[4] * 1.1;  // apex 5 above apex 4
  const auto points = MeasureRestitution(h, std::vector<double>(h.size(), 0.001), 0, 0);
  const RestitutionConsistency c = CheckRestitution(points);
  ASSERT_FALSE(c.suspect.empty());
  EXPECT_NE(c.suspect.front().find("bounce 5"), std::string::npos) << c.suspect.front();
  EXPECT_NE(c.suspect.front().find("above 1"), std::string::npos) << c.suspect.front();
}

// Nothing to measure: no crash, no claim.
TEST(RestitutionPoints, TooFewApexes) {
  EXPECT_TRUE(MeasureRestitution({0.5}, {}, 0.1, 0).empty());
  const RestitutionConsistency none = CheckRestitution({});
  EXPECT_EQ(none.points, 0);
  EXPECT_TRUE(none.drops_agree);
  const auto one = MeasureRestitution({0.564, 0.262}, {0.002, 0.003}, 0.03, 0);
  const RestitutionConsistency c = CheckRestitution(one);
  EXPECT_EQ(c.points, 1);
  EXPECT_NEAR(c.e0, one[0].e, 1e-9);
  EXPECT_TRUE(std::isnan(c.sigma_k));
}

}  // namespace
}  // namespace bouncefit
