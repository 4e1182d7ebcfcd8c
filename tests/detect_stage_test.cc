// The detect stage (pipeline/detect_stage.h) over real LCM traffic (memq://): STREAM and
// BALL_BOX in; CALIBRATION, BOUNCE_PEAK (live, then refitted at the drop's end, then the rows),
// DROP out, with the detector's own peaks; peaks.csv, calibration.json and summary.json
// written; a garbled BALL_BOX packet counted and ignored; times going backwards start a
// fresh detector.
#include "pipeline/detect_stage.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>

#include "detect/capture_clock_detector.h"
#include "msgs/lcm_bus.h"
#include "pipeline/message_mapping.h"
#include "tests/detect_sim.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

// What the stage sent on the bus.
struct Heard {
  std::vector<bounce_peak_t> peaks;
  std::vector<calibration_t> calibrations;
  std::vector<drop_t> drops;
  explicit Heard(LcmBus& bus) {
    bus.Subscribe<bounce_peak_t>("BOUNCE_PEAK", [this](const bounce_peak_t& m) { peaks.push_back(m); });
    bus.Subscribe<calibration_t>("CALIBRATION", [this](const calibration_t& m) { calibrations.push_back(m); });
    bus.Subscribe<drop_t>("DROP", [this](const drop_t& m) { drops.push_back(m); });
  }
  std::vector<bounce_peak_t> Revision(int r) const {
    std::vector<bounce_peak_t> out;
    std::copy_if(peaks.begin(), peaks.end(), std::back_inserter(out), [r](const bounce_peak_t& m) { return m.revision == r; });
    return out;
  }
};

// The detector the stage runs for a stream of this size and ball, alone, in-process.
CaptureClockDetector ReferenceDetector(const BallPreset& ball, const testing::SimOptions& o) {
  BounceDetectorConfig c;
  c.calibration.ball_diameter_m = ball.diameter_m;
  c.image_width_px = static_cast<int>(o.width);
  c.image_height_px = static_cast<int>(o.height);
  return CaptureClockDetector(c, FrameRetimingConfig{});
}

stream_t StreamMsg(const std::string& state, int64_t utime, const testing::SimOptions& o) {
  stream_t m{};
  m.utime = utime;
  m.state = state;
  m.input = "sim";
  m.nominal_fps = o.fps;
  m.width = static_cast<int>(o.width);
  m.height = static_cast<int>(o.height);
  m.sound = "no sound track";
  return m;
}

TEST(DetectStage, BoxesInPeaksCalibrationDropsAndFilesOut) {
  testing::SimOptions o;
  o.ball = "airball";
  o.drop_m = 1.2;
  o.roll_deg = 1;
  const auto clip = testing::MakeSimClip(o);
  const BallPreset ball = *FindBallPreset("airball");
  CaptureClockDetector core = ReferenceDetector(ball, o);
  const auto expected = testing::RunDetector(core, clip.obs);
  ASSERT_GE(expected.size(), 5u);

  const auto dir = testing::ScratchDir("out");
  LcmBus bus("memq://");
  Heard heard(bus);
  DetectStageConfig cfg;
  cfg.ball = ball;
  cfg.out_dir = dir;
  DetectStage stage(cfg, bus);
  bus.Publish("STREAM", StreamMsg("start", clip.obs.front().utime, o));
  const uint8_t garbage[] = {0xde, 0xad, 0xbe, 0xef, 1, 2, 3};
  for (size_t i = 0; i < clip.obs.size(); ++i) {
    bus.Publish("BALL_BOX", ToBallBox(clip.obs[i]));
    if (i == 40) bus.raw().publish("BALL_BOX", garbage, sizeof garbage);
    bus.Drain();
  }
  bus.Publish("STREAM", StreamMsg("end", clip.obs.back().utime, o));
  bus.Drain();
  ASSERT_TRUE(stage.done());
  EXPECT_EQ(stage.fatal(), "");
  EXPECT_EQ(bus.decode_failures(), 1);
  EXPECT_EQ(stage.boxes(), static_cast<int>(clip.obs.size()));

  // Each apex live, as the detector gives it.
  const auto live = heard.Revision(0);
  ASSERT_EQ(live.size(), expected.size());
  for (size_t i = 0; i < live.size(); ++i) {
    EXPECT_EQ(live[i].bounce, expected[i].bounce);
    EXPECT_EQ(live[i].apex_utime, expected[i].apex_utime);
    EXPECT_DOUBLE_EQ(live[i].height_m, expected[i].height_m);
    EXPECT_EQ(live[i].emitted_utime, expected[i].emitted_utime);
  }
  const auto score = testing::ScorePeaks(clip, expected);
  EXPECT_EQ(score.found_over_1cm, score.truth_over_1cm) << score.report;
  EXPECT_EQ(score.false_peaks, 0) << score.report;
  // When the drop ended, each again with its height refitted with every arc (the detector's
  // summary of the drop), at the live apex's pixel scale.
  ASSERT_FALSE(core.detector().Summaries().empty());
  const SequenceSummary& drop = core.detector().Summaries().back();
  const auto refits = heard.Revision(2);
  EXPECT_GE(refits.size(), live.size() - 1);  // all but the release, at least
  for (const bounce_peak_t& r : refits) {
    const size_t k = static_cast<size_t>(r.bounce - drop.first_bounce);
    ASSERT_LT(k, drop.final_height_m.size());
    EXPECT_DOUBLE_EQ(r.height_m, drop.final_height_m[k]) << "bounce " << r.bounce;
    const auto l = std::find_if(live.begin(), live.end(), [&](const bounce_peak_t& m) { return m.bounce == r.bounce; });
    ASSERT_NE(l, live.end());
    EXPECT_GE(r.emitted_utime, live.back().emitted_utime);
    EXPECT_NEAR(r.height_px / r.height_m, l->height_px / l->height_m, 1e-6 * l->height_px / l->height_m);
  }
  // The scale from the free fall.
  ASSERT_FALSE(heard.calibrations.empty());
  const calibration_t& cal = heard.calibrations.back();
  EXPECT_EQ(cal.method, "free-fall");
  EXPECT_NEAR(cal.px_per_m, o.px_per_m, 0.01 * o.px_per_m);
  EXPECT_NEAR(cal.roll_rad, o.roll_deg * M_PI / 180, 0.005);
  // The drop ended, then the stream: DROP says how many rows peaks.csv has.
  ASSERT_EQ(heard.drops.size(), 2u);
  EXPECT_EQ(heard.drops[0].state, "ended");
  EXPECT_EQ(heard.drops[1].state, "done");
  EXPECT_EQ(heard.drops[1].reason, "end of stream");
  EXPECT_EQ(heard.drops[1].peaks, stage.rows());

  // The files: the rows as sent (revision 3), the last calibration, the stream's summary.
  const auto rows = heard.Revision(3);
  EXPECT_EQ(static_cast<int>(rows.size()), stage.rows());
  const auto csv = testing::ReadCsv(dir / "peaks.csv");
  ASSERT_EQ(csv.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(csv[i].at("bounce"), std::to_string(rows[i].bounce));
  std::ifstream cal_file(dir / "calibration.json");
  const nlohmann::json cal_json = nlohmann::json::parse(cal_file);
  EXPECT_DOUBLE_EQ(cal_json.at("px_per_m").get<double>(), cal.px_per_m);
  std::ifstream summary_file(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary.at("rows").get<int>(), stage.rows());
  EXPECT_EQ(summary.at("peaks").size(), live.size());
  ASSERT_EQ(summary.at("drops").size(), 1u);
  EXPECT_EQ(summary.at("drops")[0].at("final_height_m").size(), drop.final_height_m.size());
}

TEST(DetectStage, TimeGoingBackwardsStartsAFreshDetector) {
  testing::SimOptions o;
  o.ball = "softball";
  const auto clip = testing::MakeSimClip(o);
  const BallPreset ball = *FindBallPreset("softball");
  CaptureClockDetector core = ReferenceDetector(ball, o);
  const size_t per_pass = testing::RunDetector(core, clip.obs).size();
  ASSERT_GE(per_pass, 3u);

  const auto dir = testing::ScratchDir("out");
  LcmBus bus("memq://");
  Heard heard(bus);
  DetectStageConfig cfg;
  cfg.ball = ball;
  cfg.frame_width_px = static_cast<int>(o.width);  // no STREAM: a log of boxes alone
  cfg.frame_height_px = static_cast<int>(o.height);
  cfg.out_dir = dir;
  DetectStage stage(cfg, bus);
  for (int pass = 0; pass < 2; ++pass)
    for (const auto& b : clip.obs) {
      bus.Publish("BALL_BOX", ToBallBox(b));
      bus.Drain();
    }
  stage.FinishWithoutEnd();
  bus.Drain();
  ASSERT_TRUE(stage.done());
  EXPECT_EQ(heard.Revision(0).size(), 2 * per_pass);
  ASSERT_EQ(heard.drops.size(), 3u);  // each pass's drop ended, then the stream
  EXPECT_EQ(heard.drops[2].reason, "the capture node went silent");
  std::ifstream summary_file(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  ASSERT_EQ(summary.at("drops").size(), 2u);
}

}  // namespace
}  // namespace bouncefit
