// report.html as a person sees it: the report of a real `bouncefit run` (its height curve
// meets the detected apexes, its sound strip the impacts heard), and opened offline in headless
// Chromium, every figure decoded and painted. The Chromium tests skip with a message when
// Chromium is not installed (scripts/setup adds it).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <fstream>
#include <regex>
#include <sstream>

#include "msgs/peaks_csv.h"
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

std::string FindChromium() {
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
    std::string out;
    if (RunCommand(std::string("command -v ") + name, &out) == 0 && !out.empty()) {
      while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
      return out;
    }
  }
  return "";
}

// Headless, offline, in a fresh profile: nothing from the network or a previous run counts.
std::string ChromiumCommand(const std::string& chromium, const fs::path& profile,
                            const std::string& action, const fs::path& html) {
  return "timeout 90 '" + chromium +
         "' --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
         "--disable-background-networking --disable-component-update --disable-sync "
         "--hide-scrollbars --user-data-dir='" + profile.string() + "' " + action +
         " 'file://" + fs::absolute(html).string() + "'";
}

class ReportInChromium : public ::testing::Test {
 protected:
  void SetUp() override {
    chromium_ = FindChromium();
    if (chromium_.empty()) GTEST_SKIP() << "chromium not installed (bash scripts/setup adds it)";
    dir_ = ScratchDir("report_chromium");
    testing::WriteReportFixture(dir_ / "run");
    std::string out;
    ASSERT_EQ(RunCommand(BouncefitExe() + " report '" + (dir_ / "run").string() + "'", &out), 0)
        << out;
    html_ = dir_ / "run" / "report.html";
  }
  std::string chromium_;
  fs::path dir_, html_;
};

TEST_F(ReportInChromium, EveryFigureDecodesInTheDom) {
  std::string dom;
  const int rc = RunCommand(ChromiumCommand(chromium_, dir_ / "profile-dom",
                                            "--virtual-time-budget=5000 --dump-dom", html_) +
                                " 2>/dev/null",
                            &dom);
  ASSERT_EQ(rc, 0) << dom.substr(0, 2000);
  // The page's own load handler counts <img class="figure"> with naturalWidth > 0.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      dom, m, std::regex("id=\"figure-status\"[^>]*data-decoded=\"(\\d+)\" data-total=\"(\\d+)\"")))
      << "no decode marker in the DOM: the page's script did not run";
  EXPECT_EQ(m[2].str(), "5");
  EXPECT_EQ(m[1].str(), m[2].str()) << "some figure did not decode";
  EXPECT_NE(dom.find("5 of 5 figures rendered."), std::string::npos);
}

TEST_F(ReportInChromium, ScreenshotShowsTheFiguresPainted) {
  const fs::path shot = dir_ / "screenshot.png";
  std::string out;
  const int rc = RunCommand(
      ChromiumCommand(chromium_, dir_ / "profile-shot",
                      "--screenshot='" + shot.string() + "' --window-size=1200,3000", html_),
      &out);
  ASSERT_EQ(rc, 0) << out;
  const cv::Mat img = cv::imread(shot.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty()) << "no screenshot at " << shot;
  EXPECT_EQ(img.cols, 1200);
  EXPECT_EQ(img.rows, 3000);
  // Not blank: a good share of the page is ink.
  cv::Mat gray;
  cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  const double ink = cv::countNonZero(gray < 200) / static_cast<double>(gray.total());
  EXPECT_GT(ink, 0.01);
  // The page's HTML and CSS use only greys: the plot colours can come only from painted
  // figures. Blue tracked height, orange simulation, red apexes (the first 3000 px of the page).
  struct Colour {
    const char* what;
    cv::Scalar bgr;
  };
  for (const Colour& c : {Colour{"blue height curve", {180, 119, 31}},
                          Colour{"orange simulation", {14, 127, 255}},
                          Colour{"red apexes", {40, 39, 214}}}) {
    cv::Mat mask;
    cv::inRange(img, c.bgr - cv::Scalar(30, 30, 30), c.bgr + cv::Scalar(30, 30, 30), mask);
    EXPECT_GT(cv::countNonZero(mask), 200) << c.what << " not on the screenshot";
  }
}

// A real `bouncefit run` of the built-in sample drop: the report reads what run writes, and
// its height curve (from track.csv and calibration.json) agrees with the detector's apexes.
TEST(ReportOfARealRun, HeightCurveMeetsTheDetectedApexes) {
  const auto dir = ScratchDir("report_real_run");
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " run --out '" + (dir / "run").string() +
                           "' --speed 0 --model point-mass -q --lcm-url '" +
                           testing::UniqueUdpmUrl() + "'", &out), 0) << out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " report -q '" + (dir / "run").string() + "'", &out), 0)
      << out;
  const ReportRunData run = LoadRunDirectory(dir / "run");
  ASSERT_TRUE(run.calibration.has_value());
  ASSERT_GE(run.peaks.size(), 5u);
  ASSERT_NE(run.FinalFit(), nullptr);
  EXPECT_FALSE(run.simulated.empty());
  for (const char* id : {"height", "trajectory", "bounces", "coefficients", "aspect"}) {
    EXPECT_TRUE(fs::exists(dir / "run" / (std::string("report_") + id + ".png"))) << id;
  }
  int compared = 0;
  for (const auto& p : run.peaks) {
    if (p.bounce < 1 || !std::isfinite(p.height_m)) continue;
    // The found frame nearest the apex: within half a frame the ball moves < 0.1 mm.
    const ReportTrackRow* nearest = nullptr;
    for (const auto& r : run.track) {
      if (r.found && (!nearest || std::abs(r.t_s - p.t_s) < std::abs(nearest->t_s - p.t_s))) {
        nearest = &r;
      }
    }
    ASSERT_NE(nearest, nullptr);
    if (std::abs(nearest->t_s - p.t_s) > 1.0 / 120) continue;
    // Box half-height vs the detector's fitted radius and pixel noise: within 5 mm
    // (2 px at 368 px/m). A wrong roll sign alone would be off by ~15 mm here.
    EXPECT_NEAR(BallBottomHeightM(*nearest, *run.calibration), p.height_m, 0.005)
        << "bounce " << p.bounce;
    ++compared;
  }
  EXPECT_GE(compared, 4);
  // The drop's refit and its flight times (summary.json) beside the live heights, in the table.
  int refitted = 0;
  for (const auto& p : run.peaks) {
    if (p.bounce < 1 || !std::isfinite(p.refit_height_m)) continue;
    EXPECT_NEAR(p.refit_height_m, p.height_m, 0.003) << "bounce " << p.bounce;
    EXPECT_NEAR(p.refit_height_m, p.flight_height_m, 0.02 * p.refit_height_m + 0.002) << "bounce " << p.bounce;
    ++refitted;
  }
  EXPECT_GE(refitted, 5);
  // peaks.csv carries them itself, the height to use (fused_height_m) being the refit here (no
  // sound in the sample).
  std::ifstream csv(dir / "run" / "peaks.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",fused_height_m,refit_height_m"), std::string::npos) << header;
  int rows_refitted = 0;
  for (const PeaksCsvRow& row : ReadPeaksCsv(dir / "run" / "peaks.csv")) {
    if (!std::isfinite(row.refit_height_m)) continue;
    EXPECT_EQ(row.fused_height_m, row.refit_height_m) << "bounce " << row.bounce;
    ++rows_refitted;
  }
  EXPECT_GE(rows_refitted, 5);
  std::ifstream html_file(dir / "run" / "report.html");
  const std::string html((std::istreambuf_iterator<char>(html_file)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("refitted height (m)"), std::string::npos);
}

// A run with sound 30 ms late: the height figure gets the waveform strip, in the video's
// clock (each heard impact on its click, not 30 ms before it), with the impacts marked.
TEST(ReportOfARealRun, SoundStripHasTheClicksUnderTheImpactsHeard) {
  const auto dir = ScratchDir("report_sound");
  std::string out;
  const std::string clip = (dir / "clip.avi").string();
  ASSERT_EQ(RunCommand(BouncefitExe() + " synth -q --sound --sound-offset 0.03 --fps 60 --duration 3 "
                           "--size 320x240 --out '" + clip + "'", &out), 0) << out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " run '" + clip + "' --no-fit --speed 0 -q --lcm-url memq:// --out '" +
                           (dir / "run").string() + "'", &out), 0) << out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " report -q '" + (dir / "run").string() + "'", &out), 0) << out;
  const ReportRunData run = LoadRunDirectory(dir / "run");
  ASSERT_GT(run.waveform.size(), 500u);  // 3 s at 5 ms
  int heard = 0;
  std::vector<double> peaks;
  for (const auto& w : run.waveform) peaks.push_back(w.peak);
  std::nth_element(peaks.begin(), peaks.begin() + peaks.size() / 2, peaks.end());
  const double median = peaks[peaks.size() / 2];
  for (const auto& i : run.impacts) {
    if (i.source == "video") continue;
    ++heard;
    double loudest = 0;  // the waveform within 10 ms of the impact
    for (const auto& w : run.waveform)
      if (std::abs(w.t_s - i.t_s) <= 0.01) loudest = std::max(loudest, w.peak);
    EXPECT_GT(loudest, 3 * median) << "no click under the impact at " << i.t_s << " s";
  }
  EXPECT_GE(heard, 3);
  std::ifstream gp_file(dir / "run" / "report_plots" / "height.gp");
  const std::string gp((std::istreambuf_iterator<char>(gp_file)), {});
  EXPECT_NE(gp.find("set multiplot"), std::string::npos) << gp;
  EXPECT_NE(gp.find("impact heard"), std::string::npos) << gp;
  const cv::Mat img = cv::imread((dir / "run" / "report_height.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  cv::Mat red;  // the impact lines (#d62728) and apex dots
  cv::inRange(img, cv::Scalar(10, 10, 190), cv::Scalar(70, 70, 240), red);
  EXPECT_GT(cv::countNonZero(red(cv::Rect(0, img.rows * 6 / 10, img.cols, img.rows * 2 / 10))), 50)
      << "no impact line in the strip";
}

}  // namespace
}  // namespace bouncefit
