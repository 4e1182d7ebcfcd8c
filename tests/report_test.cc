// The report core and `bouncefit report` on a run directory computed from physics.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <sstream>

#include "report/report_html.h"
#include "report/report_run_data.h"
#include "tests/report_fixture.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;
using testing::ScratchDir;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

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

TEST(Report, Base64MatchesKnownVectors) {
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64Encode(std::string("\xff\x00\x10", 3)), "/wAQ");
}

TEST(Report, FullRunGivesEveryFigureEmbeddedInOneSelfContainedPage) {
  const auto dir = ScratchDir("report_full");
  testing::WriteReportFixture(dir);
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " report '" + dir.string() + "'", &out), 0) << out;
  const char* ids[] = {"height", "trajectory", "bounces", "coefficients", "aspect"};
  const std::string html = Slurp(dir / "report.html");
  for (const char* id : ids) {
    const fs::path png = dir / (std::string("report_") + id + ".png");
    const cv::Mat img = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << png;
    EXPECT_GE(img.cols, 1000) << id;
    // Not blank: a plot has dark ink (axes, text, curves) on a light background.
    EXPECT_GT(cv::countNonZero(img < 128), 500) << id;
    EXPECT_NE(html.find(std::string("id=\"fig-") + id + "\""), std::string::npos) << id;
    // The very bytes of the PNG are in the page.
    EXPECT_NE(html.find(Base64Encode(Slurp(png)).substr(0, 2000)), std::string::npos) << id;
  }
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("src=\"file"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  // Tables, with units.
  EXPECT_NE(html.find("400.00</td><td>1.20</td><td>px/m"), std::string::npos);
  EXPECT_NE(html.find("<code>restitution</code>"), std::string::npos);
  EXPECT_NE(html.find("s/m"), std::string::npos);  // unit from coefficients.json
  EXPECT_NE(html.find("kRestitutionPerMps"), std::string::npos);  // soft_body_config.cc
  EXPECT_NE(html.find("e at low impact speed"), std::string::npos);  // note from the export
  EXPECT_NE(html.find("0.79</td><td>0.00167</td><td>-</td>"), std::string::npos)
      << "dimensionless unit";
  EXPECT_NE(html.find("0.800"), std::string::npos);                // restitution column
  EXPECT_NE(html.find("<b>no</b>"), std::string::npos);            // spin_damping
  // Apex labels drawn by gnuplot come from peaks.csv.
  const std::string apexes = Slurp(dir / "report_plots" / "apexes.dat");
  EXPECT_NE(apexes.find("\"1: 0.640 m\""), std::string::npos) << apexes;
}

TEST(Report, RunWithoutFitStillReportsWhatItHas) {
  const auto dir = ScratchDir("report_nofit");
  testing::ReportFixtureOptions opt;
  opt.fits = false;
  opt.simulated = false;
  opt.exports = false;
  testing::WriteReportFixture(dir, opt);
  fs::remove(dir / "summary.json");
  ReportOptions options;
  const auto outcome = WriteReport(dir, options);
  ASSERT_EQ(outcome.figures.size(), 3u);  // height, bounces, aspect
  EXPECT_EQ(outcome.skipped.size(), 2u);
  const std::string html = Slurp(outcome.html);
  EXPECT_NE(html.find("No fit yet (fit.jsonl absent)"), std::string::npos);
  EXPECT_NE(html.find("simulated.csv absent"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "report_trajectory.png"));
}

TEST(Report, CoefficientHistoryIsTheFinalModelsOnly) {
  const auto dir = ScratchDir("report_two_models");
  testing::WriteReportFixture(dir);
  const std::string fits = Slurp(dir / "fit.jsonl");
  std::ofstream(dir / "fit.jsonl")
      << "{\"after_bounce\":1,\"final\":false,\"model\":\"quick-model\",\"method\":\"x\","
         "\"coefficients\":[{\"name\":\"other_coefficient\",\"value\":3}],"
         "\"residual_m\":0.5}\n"
      << fits;
  const auto outcome = WriteReport(dir, ReportOptions{});
  const std::string gp = Slurp(dir / "report_plots" / "coefficients.gp");
  EXPECT_EQ(gp.find("other_coefficient"), std::string::npos) << gp;
  EXPECT_NE(gp.find("'restitution'"), std::string::npos) << gp;
  EXPECT_NE(gp.find("point-mass model"), std::string::npos) << gp;
  // 500 mm of the other model's residual is not on the residual panel.
  EXPECT_EQ(Slurp(dir / "report_plots" / "residual.dat").find(" 500 "), std::string::npos);
  // The history table still lists every fit.
  EXPECT_NE(Slurp(outcome.html).find("quick-model"), std::string::npos);
}

TEST(Report, NoCalibrationPlotsPixels) {
  const auto dir = ScratchDir("report_nocal");
  testing::ReportFixtureOptions opt;
  opt.calibration = false;
  testing::WriteReportFixture(dir, opt);
  const auto outcome = WriteReport(dir, ReportOptions{});
  EXPECT_GE(outcome.figures.size(), 4u);
  const std::string gp = Slurp(dir / "report_plots" / "height.gp");
  EXPECT_NE(gp.find("(px)"), std::string::npos);
}

TEST(Report, RelativeDirectoryKeepsGnuplotChatterInItsLog) {
  const auto dir = ScratchDir("report_relative");
  testing::WriteReportFixture(dir);  // a constant coefficient makes gnuplot warn
  std::string out;
  ASSERT_EQ(RunCommand("cd '" + dir.parent_path().string() + "' && " + BouncefitExe() +
                           " report -q report_relative", &out), 0) << out;
  EXPECT_EQ(out, "");
  EXPECT_NE(Slurp(dir / "report_plots" / "coefficients.gp.log").find("Warning"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "report.html"));
}

TEST(Report, CliErrorsAreOneLineNamingTheCause) {
  const auto dir = ScratchDir("report_cli_errors");
  std::string out;
  EXPECT_EQ(RunCommand(BouncefitExe() + " report '" + dir.string() + "'", &out), 1);
  EXPECT_EQ(Lines(out), 1) << out;
  EXPECT_NE(out.find("track.csv"), std::string::npos) << out;

  testing::WriteReportFixture(dir);
  EXPECT_EQ(RunCommand(BouncefitExe() + " report --gnuplot /nonexistent/gnuplot '" +
                           dir.string() + "'", &out), 1);
  EXPECT_EQ(Lines(out), 1) << out;
  EXPECT_NE(out.find("gnuplot not found"), std::string::npos) << out;

  std::ofstream(dir / "fit.jsonl") << "{oops\n";
  EXPECT_EQ(RunCommand(BouncefitExe() + " report '" + dir.string() + "'", &out), 1);
  EXPECT_EQ(Lines(out), 1) << out;
  EXPECT_NE(out.find("fit.jsonl: line 1"), std::string::npos) << out;
}

}  // namespace
}  // namespace bouncefit
