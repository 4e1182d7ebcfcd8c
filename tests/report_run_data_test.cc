// The report's reading of a run directory (report/report_run_data.h), on one computed from
// physics: every file read, heights and restitution as the physics gives them, broken files
// as one-line errors naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "report/report_run_data.h"
#include "tests/report_fixture.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::ScratchDir;

TEST(ReportRunData, ReadsEveryFileOfTheFixture) {
  const auto dir = ScratchDir("report_read");
  const auto truth = testing::WriteReportFixture(dir);
  const auto run = LoadRunDirectory(dir);
  EXPECT_EQ(run.track.size(), 360u);
  ASSERT_EQ(run.peaks.size(), truth.apex_height_m.size());
  ASSERT_GE(run.peaks.size(), 4u);
  ASSERT_TRUE(run.calibration.has_value());
  EXPECT_DOUBLE_EQ(run.calibration->px_per_m, 400.0);
  EXPECT_EQ(run.calibration->method, "free-fall");
  ASSERT_NE(run.FinalFit(), nullptr);
  EXPECT_TRUE(run.FinalFit()->final);
  EXPECT_EQ(run.FinalFit()->coefficients.size(), 3u);
  EXPECT_TRUE(std::isnan(run.FinalFit()->coefficients[2].sigma));  // null -> NaN
  EXPECT_FALSE(run.FinalFit()->coefficients[2].identifiable);
  EXPECT_EQ(run.simulated.size(), 360u);
  EXPECT_TRUE(run.summary.has_value());
  EXPECT_FALSE(run.fit_export_cc.empty());
  EXPECT_TRUE(run.absent_files.empty());
  EXPECT_TRUE(std::isnan(run.track[50].cy_px));  // a frame where the ball was lost
  EXPECT_FALSE(run.track[50].found);
}

TEST(ReportRunData, HeightFromBoxesMatchesThePhysics) {
  const auto dir = ScratchDir("report_height");
  const auto truth = testing::WriteReportFixture(dir);
  const auto run = LoadRunDirectory(dir);
  int checked = 0;
  for (const auto& r : run.track) {
    if (!r.found) continue;
    const double h = BallBottomHeightM(r, *run.calibration);
    // Boxes are whole pixels: within half a pixel (1.25 mm at 400 px/m).
    EXPECT_NEAR(h, testing::FixtureHeight(truth, truth.restitution, r.t_s), 0.5 / 400 + 1e-6)
        << r.t_s;
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

TEST(ReportRunData, RollProjectsTheCentreOnTrueDown) {
  ReportCalibration c;
  c.px_per_m = 100;
  c.floor_px = 500;
  c.roll_rad = 0;
  EXPECT_NEAR(BallBottomHeightM(100, 390, 20, c), 1.0, 1e-12);
  // A camera rolled by 90 degrees: true down is image +x.
  c.roll_rad = M_PI / 2;
  EXPECT_NEAR(BallBottomHeightM(390, 7, 20, c), 1.0, 1e-9);
  c.px_per_m = kReportNaN;
  EXPECT_TRUE(std::isnan(BallBottomHeightM(100, 390, 20, c)));
}

TEST(ReportRunData, RestitutionFromHeightsAndFlights) {
  const auto dir = ScratchDir("report_restitution");
  testing::WriteReportFixture(dir);
  const auto run = LoadRunDirectory(dir);
  const auto e = RestitutionFromHeights(run.peaks);
  const auto ef = RestitutionFromFlights(run.peaks);
  EXPECT_TRUE(std::isnan(e[0]));
  for (size_t i = 1; i < e.size(); ++i) EXPECT_NEAR(e[i], 0.8, 1e-4) << i;
  ASSERT_GE(ef.size(), 3u);
  EXPECT_NEAR(ef[2], 0.8, 1e-4);
}

// The heights the final fit took (peaks.csv's fused_height_m: a bounce heard end to end its
// flight-time height, else the drop's refit), else the live one of a file without them.
TEST(ReportRunData, RestitutionFromTheHeightsTheFitTook) {
  std::vector<ReportPeak> peaks(4);
  for (int b = 0; b < 4; ++b) peaks[b].bounce = b, peaks[b].height_m = 1.0 - 0.2 * b;
  peaks[1].refit_height_m = peaks[1].fused_height_m = 0.64;  // live 0.8
  peaks[2].fused_height_m = 0.4096;  // heard; live 0.6
  peaks[2].refit_height_m = 0.5;     // the heard height wins
  const auto e = RestitutionFromHeights(peaks);
  EXPECT_NEAR(e[1], 0.8, 1e-9);
  EXPECT_NEAR(e[2], 0.8, 1e-9);
  EXPECT_NEAR(e[3], std::sqrt(0.4 / 0.4096), 1e-9);  // bounce 3: live only
}

TEST(ReportRunData, MissingTrackIsAnErrorNamingTheFile) {
  const auto dir = ScratchDir("report_missing");
  try {
    LoadRunDirectory(dir);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("track.csv"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadRunDirectory(dir / "nope"), std::runtime_error);
}

void ExpectGarbledNamed(const std::string& file, const std::string& content,
                        const std::string& also) {
  const auto dir = ScratchDir("report_garbled");
  testing::WriteReportFixture(dir);
  std::ofstream(dir / file) << content;
  try {
    LoadRunDirectory(dir);
    ADD_FAILURE() << file << ": no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << what;
    EXPECT_NE(what.find(also), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(ReportRunData, GarbledFilesAreOneLineErrorsNamingTheFile) {
  ExpectGarbledNamed("peaks.csv", "bounce,t_s,height_m\n1,0.5,abc\n", "line 2");
  ExpectGarbledNamed("peaks.csv", "bounce,t_s\n1,0.5\n", "height_m");
  ExpectGarbledNamed("track.csv", "frame,t_s,found\n0,0.0,1\n1,0.1\n", "line 3");
  ExpectGarbledNamed("calibration.json", "{\"px_per_m\": 400", "JSON");
  ExpectGarbledNamed("fit.jsonl", "{\"after_bounce\": 1}\nnot json\n", "line 2");
  ExpectGarbledNamed("simulated.csv", "t_s,height_m\n0.0,x\n", "simulated.csv");
}

TEST(ReportRunData, HalfWrittenLastLineOfARunInProgressIsIgnored) {
  const auto dir = ScratchDir("report_partial");
  testing::WriteReportFixture(dir);
  std::ofstream(dir / "track.csv", std::ios::app) << "360,3.0000,1,320.0";
  const auto run = LoadRunDirectory(dir);
  EXPECT_EQ(run.track.size(), 360u);
}

}  // namespace
}  // namespace bouncefit
