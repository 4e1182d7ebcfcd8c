// The streaming bounce detector on tracker-like observations of point-mass drops with drag
// (the synth physics): every apex found, no false peaks, heights within max(2 mm, 1%) with
// the detector's own calibration, latency bounded; hold, gaps, second drop, noise.
#include "track/bounce_detector.h"

#include <gtest/gtest.h>

#include "tests/detect_sim.h"

namespace bouncefit {
namespace {

using testing::MakeSimClip;
using testing::PeakScore;
using testing::RunDetector;
using testing::ScorePeaks;
using testing::SimOptions;

struct Case {
  std::string ball;
  double drop_m;
  double fps;
  double roll_deg;
};

class DetectorPresets : public ::testing::TestWithParam<Case> {};

TEST_P(DetectorPresets, FindsEveryApexAccuratelyAndPromptly) {
  const Case c = GetParam();
  SimOptions o;
  o.ball = c.ball;
  o.drop_m = c.drop_m;
  o.fps = c.fps;
  o.roll_deg = c.roll_deg;
  o.seed = static_cast<unsigned>(c.drop_m * 100 + c.fps + c.ball.size());
  const auto clip = MakeSimClip(o);
  BounceDetectorConfig cfg;
  BounceDetector d(cfg);
  const auto peaks = RunDetector(d, clip.obs);
  const PeakScore s = ScorePeaks(clip, peaks);
  const double med = testing::Median(s.latency_frames);
  double max_lat = 0;
  for (double l : s.latency_frames) max_lat = std::max(max_lat, l);
  const auto& cal = d.calibration();
  const double cal_err = (cal.px_per_m / o.px_per_m - 1) * 100;
  std::printf("%s", s.report.c_str());
  std::printf("%s %.1f m %g fps roll %g: %d/%d apexes, %d false, max err %.2f mm, cal %+.3f%%, "
              "roll err %.3f deg, latency median %.2f max %.2f, bounce0 %.1f frames after impact\n",
              c.ball.c_str(), c.drop_m, c.fps, c.roll_deg, s.found_over_1cm, s.truth_over_1cm,
              s.false_peaks, s.max_err_mm, cal_err, cal.roll_rad * 180 / M_PI - c.roll_deg, med,
              max_lat, s.bounce0_latency_from_impact_frames);
  EXPECT_EQ(s.found_over_1cm, s.truth_over_1cm) << s.report;
  EXPECT_EQ(s.false_peaks, 0) << s.report;
  EXPECT_TRUE(s.within_tolerance) << s.report;
  EXPECT_LE(med, 2.0) << s.report;
  EXPECT_LE(max_lat, 4.0) << s.report;
  EXPECT_LT(std::abs(cal_err), 1.0);
  EXPECT_LT(std::abs(cal.roll_rad * 180 / M_PI - c.roll_deg), 0.2);
}

INSTANTIATE_TEST_SUITE_P(
    AllPresets, DetectorPresets,
    ::testing::Values(Case{"pingpong", 1.0, 120, 0}, Case{"pingpong", 1.6, 120, 2},
                      Case{"wiffle", 1.0, 120, -1}, Case{"wiffle", 1.6, 120, 2},
                      Case{"softball", 1.0, 120, 2}, Case{"softball", 1.6, 120, 0},
                      Case{"airball", 1.0, 120, 1.5}, Case{"airball", 1.6, 120, -2},
                      Case{"pingpong", 1.6, 60, 2}, Case{"airball", 1.0, 60, 0}),
    [](const ::testing::TestParamInfo<Case>& i) {
      return i.param.ball + "_" + std::to_string(static_cast<int>(i.param.drop_m * 10)) + "dm_" +
             std::to_string(static_cast<int>(i.param.fps)) + "fps";
    });

}  // namespace
}  // namespace bouncefit
