// The report page (report/report_html.h) and `bouncefit report` on a run directory computed
// from physics: every figure embedded in one self-contained page, what a run without a fit
// has, the gnuplot and command-line errors.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <sstream>

#include "report/report_html.h"
#include "tests/report_fixture.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

namespace fs = std::filesystem;
using testing::BouncefitExe;
using testing::RunCommand;
using testing::ScratchDir;

int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

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
  const std::string html = testing::ReadFile(dir / "report.html");
  for (const char* id : ids) {
    const fs::path png = dir / (std::string("report_") + id + ".png");
    const cv::Mat img = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << png;
    EXPECT_GE(img.cols, 1000) << id;
    // Not blank: a plot has dark ink (axes, text, curves) on a light background.
    EXPECT_GT(cv::countNonZero(img < 128), 500) << id;
    EXPECT_NE(html.find(std::string("id=\"fig-") + id + "\""), std::string::npos) << id;
    // The very bytes of the PNG are in the page.
    EXPECT_NE(html.find(Base64Encode(testing::ReadFile(png)).substr(0, 2000)), std::string::npos) << id;
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
  const std::string apexes = testing::ReadFile(dir / "report_plots" / "apexes.dat");
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
  const std::string html = testing::ReadFile(outcome.html);
  EXPECT_NE(html.find("No fit yet (fit.jsonl absent)"), std::string::npos);
  EXPECT_NE(html.find("simulated.csv absent"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "report_trajectory.png"));
}

TEST(Report, CoefficientHistoryIsTheFinalModelsOnly) {
  const auto dir = ScratchDir("report_two_models");
  testing::WriteReportFixture(dir);
  const std::string fits = testing::ReadFile(dir / "fit.jsonl");
  std::ofstream(dir / "fit.jsonl")
      << "{\"after_bounce\":1,\"final\":false,\"model\":\"quick-model\",\"method\":\"x\","
         "\"coefficients\":[{\"name\":\"other_coefficient\",\"value\":3}],"
         "\"residual_m\":0.5}\n"
      << fits;
  const auto outcome = WriteReport(dir, ReportOptions{});
  const std::string gp = testing::ReadFile(dir / "report_plots" / "coefficients.gp");
  EXPECT_EQ(gp.find("other_coefficient"), std::string::npos) << gp;
  EXPECT_NE(gp.find("'restitution'"), std::string::npos) << gp;
  EXPECT_NE(gp.find("point-mass model"), std::string::npos) << gp;
  // 500 mm of the other model's residual is not on the residual panel.
  EXPECT_EQ(testing::ReadFile(dir / "report_plots" / "residual.dat").find(" 500 "), std::string::npos);
  // The history table still lists every fit.
  EXPECT_NE(testing::ReadFile(outcome.html).find("quick-model"), std::string::npos);
}

TEST(Report, NoCalibrationPlotsPixels) {
  const auto dir = ScratchDir("report_nocal");
  testing::ReportFixtureOptions opt;
  opt.calibration = false;
  testing::WriteReportFixture(dir, opt);
  const auto outcome = WriteReport(dir, ReportOptions{});
  EXPECT_GE(outcome.figures.size(), 4u);
  const std::string gp = testing::ReadFile(dir / "report_plots" / "height.gp");
  EXPECT_NE(gp.find("(px)"), std::string::npos);
}

TEST(Report, RelativeDirectoryKeepsGnuplotChatterInItsLog) {
  const auto dir = ScratchDir("report_relative");
  testing::WriteReportFixture(dir);  // a constant coefficient makes gnuplot warn
  std::string out;
  ASSERT_EQ(RunCommand("cd '" + dir.parent_path().string() + "' && " + BouncefitExe() +
                           " report -q report_relative", &out), 0) << out;
  EXPECT_EQ(out, "");
  EXPECT_NE(testing::ReadFile(dir / "report_plots" / "coefficients.gp.log").find("Warning"), std::string::npos);
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
