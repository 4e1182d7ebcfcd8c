// The apexes of a rendered drop as the ledger emits them (parts wired by
// tests/detector_parts.h): in bounce order, each a frame past its apex, measured to the
// truth; and revised with the whole drop at its end.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "detect/bounce_detector.h"
#include "detect_sim.h"
#include "detector_parts.h"

namespace bouncefit {
namespace {

TEST(ApexLedger, EmitsEveryApexInBounceOrderMeasuredToTheTruth) {
  testing::SimOptions o;  // ping-pong, 1 m, 120 fps, 300 px/m
  const auto clip = testing::MakeSimClip(o);
  testing::PartsHost host;
  const auto events = host.Run(clip.obs);
  std::vector<BouncePeak> peaks;
  for (const auto& e : events)
    if (e.kind == DetectorEvent::Kind::kPeak) peaks.push_back(e.peak);
  ASSERT_GE(peaks.size(), 6u);
  for (size_t i = 0; i < peaks.size(); ++i) EXPECT_EQ(peaks[i].bounce, static_cast<int>(i));
  const auto score = testing::ScorePeaks(clip, peaks);
  EXPECT_EQ(score.false_peaks, 0) << score.report;
  EXPECT_LT(score.max_err_mm, 5) << score.report;
  // A rebound goes out the frame after its fitted apex, or the next.
  for (double late : score.latency_frames) EXPECT_LT(late, 4) << score.report;
}

TEST(ApexLedger, TheDropsSummaryRevisesEveryApexWithTheWholeDrop) {
  testing::SimOptions o;
  const auto clip = testing::MakeSimClip(o);
  testing::PartsHost host;
  host.Run(clip.obs);
  const auto& summaries = host.ledger.summaries();
  ASSERT_EQ(summaries.size(), 1u);
  const SequenceSummary& s = summaries[0];
  EXPECT_EQ(s.end_reason, "rest");
  ASSERT_GE(s.peaks.size(), 6u);
  for (size_t b = 1; b < 6; ++b) {
    const double truth = clip.truth.apex_heights_m[b];
    EXPECT_NEAR(s.FinalHeightOf(static_cast<int>(b)), truth, 0.005) << "bounce " << b;
    // The flight time between its impacts says the same height, drag aside.
    EXPECT_NEAR(s.FlightHeightOf(static_cast<int>(b)), truth, 0.05 * truth) << "bounce " << b;
    EXPECT_GT(s.peaks[b].impact_after_utime, s.peaks[b].apex_utime);
  }
  EXPECT_GE(s.impacts.size(), 5u);
  EXPECT_TRUE(std::isfinite(s.restitution_intercept));
}

// A scale 20% off (a user's wrong --px-per-m): every rebound the picture measures 20% high
// disagrees with the flight times around it. Held until the impact after it, it goes out with
// the flight's height, which needs the clock only.
TEST(ApexLedger, ARebound20PercentOffItsFlightGoesOutWithTheFlightsHeight) {
  testing::SimOptions o;  // ping-pong, 1 m, 120 fps, 300 px/m
  const auto clip = testing::MakeSimClip(o);
  std::vector<SequenceSummary> summaries;
  auto run = [&](double sigmas) {
    BounceDetectorConfig c;
    c.calibration.px_per_m = 0.8 * o.px_per_m;
    c.flight_check_sigmas = sigmas;
    BounceDetector d{c};
    const auto peaks = testing::RunDetector(d, clip.obs);
    summaries = d.Summaries();
    return peaks;
  };
  int rebounds = 0;
  for (const BouncePeak& p : run(3)) {
    const auto b = static_cast<size_t>(p.bounce);
    if (b < 1 || b >= clip.truth.apex_heights_m.size() || clip.truth.apex_heights_m[b] < 0.05) continue;
    ++rebounds;
    EXPECT_NEAR(p.height_m, clip.truth.apex_heights_m[b], 0.02 * clip.truth.apex_heights_m[b]) << "bounce " << b;
    // Out once the impact that ends its flight was seen.
    EXPECT_GT(p.utime * 1e-6, clip.truth.impact_times_s[b]) << "bounce " << b;
    // Revised with the whole drop, the same.
    ASSERT_FALSE(summaries.empty());
    EXPECT_NEAR(summaries[0].FinalHeightOf(p.bounce), clip.truth.apex_heights_m[b], 0.02 * clip.truth.apex_heights_m[b])
        << "bounce " << b;
  }
  EXPECT_GE(rebounds, 5);
  // Unchecked, the picture's heights are the scale's: 25% high.
  for (const BouncePeak& p : run(0)) {
    const auto b = static_cast<size_t>(p.bounce);
    if (b >= 1 && b < clip.truth.apex_heights_m.size() && clip.truth.apex_heights_m[b] >= 0.05) {
      EXPECT_GT(p.height_m, 1.2 * clip.truth.apex_heights_m[b]) << "bounce " << b;
    }
  }
}

// After the third rebound's impact a hand tosses the ball back up, three times as high as that
// rebound rose: no ball bounces higher than it fell, so that arc is no bounce, and the three
// before it stand.
TEST(ApexLedger, ARiseFarHigherThanTheReboundBeforeIsAHandNotABounce) {
  testing::SimOptions o;  // ping-pong, 1 m, 120 fps, 300 px/m
  testing::SimClip clip = testing::MakeSimClip(o);
  const double t_impact = clip.truth.impact_times_s[3];
  const double h = 3 * clip.truth.apex_heights_m[3];
  const double g = 9.81, v = std::sqrt(2 * g * h), t_land = t_impact + 2 * v / g;
  std::vector<BallObservation> obs;
  for (BallObservation b : clip.obs) {
    const double t = b.utime * 1e-6;
    if (t > t_land) break;
    if (t > t_impact) {
      const double tau = t - t_impact;
      double x, y;
      testing::SimImagePoint(o, v * tau - 0.5 * g * tau * tau, clip.radius_px / o.px_per_m, &x, &y);
      b.cx = static_cast<float>(x), b.cy = static_cast<float>(y);
    }
    obs.push_back(b);
  }
  testing::PartsHost host;
  std::vector<int> bounces;
  for (const auto& e : host.Run(obs))
    if (e.kind == DetectorEvent::Kind::kPeak) bounces.push_back(e.peak.bounce);
  EXPECT_EQ(bounces, (std::vector<int>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace bouncefit
