// LCM logs: the strict reader (lcm-logger format), paced republishing, corrupt logs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "bouncefit/ball_box_t.hpp"
#include "msgs/lcm_bus.h"
#include "msgs/lcm_log_recorder.h"
#include "pipeline/lcm_log_replay.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

class FakeClock : public PacerClock {
 public:
  int64_t NowMicros() override { return now; }
  void SleepUntilMicros(int64_t deadline) override {
    if (deadline > now) now = deadline;
  }
  int64_t now = 0;
};

std::vector<uint8_t> Box(int64_t frame) {
  ball_box_t m{};
  m.utime = 1000000 + frame * 8333;
  m.frame = frame;
  m.found = true;
  m.cx = 100.5f + frame;
  std::vector<uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// 100 BALL_BOX events every 10 ms, a CALIBRATION every 25th, written by our recorder (the
// lcm::LogFile writer underneath, as lcm-logger uses).
std::string WriteLog(const std::filesystem::path& dir) {
  const std::string path = (dir / "session.lcm").string();
  LcmLogRecorder rec(path);
  for (int i = 0; i < 100; ++i) {
    const auto b = Box(i);
    rec.Record("BALL_BOX", b.data(), b.size(), 5000000 + i * 10000);
    if (i % 25 == 0) rec.Record("CALIBRATION", "xyz", 3, 5000000 + i * 10000 + 1);
  }
  rec.Close();
  return path;
}

struct Published {
  std::string channel;
  std::vector<uint8_t> data;
  int64_t at;
};

TEST(LcmLogReader, ReadsWhatLcmWrote) {
  const auto dir = testing::ScratchDir("lcm_log_reader");
  LcmLogReader reader(WriteLog(dir));
  int boxes = 0, others = 0;
  int64_t last = 0;
  while (auto e = reader.Next()) {
    EXPECT_GE(e->utime, last);
    last = e->utime;
    if (e->channel == "BALL_BOX") {
      EXPECT_EQ(e->data, Box(boxes));
      EXPECT_EQ(e->utime, 5000000 + boxes * 10000);
      ++boxes;
    } else {
      EXPECT_EQ(e->channel, "CALIBRATION");
      ++others;
    }
  }
  EXPECT_EQ(boxes, 100);
  EXPECT_EQ(others, 4);
  EXPECT_EQ(reader.events_read(), 104);
}

TEST(LogReplay, RepublishesWithTheLoggedPacingScaled) {
  const auto dir = testing::ScratchDir("lcm_log_pacing");
  const std::string log = WriteLog(dir);
  for (double speed : {1.0, 2.0, 0.0}) {
    FakeClock clock;
    clock.now = 777;
    std::vector<Published> out;
    LogReplayStats stats;
    LogReplayConfig c;
    c.speed = speed;
    ReplayLcmLog(log, c,
                 [&](const std::string& ch, const void* d, std::size_t n) {
                   const auto* p = static_cast<const uint8_t*>(d);
                   out.push_back({ch, std::vector<uint8_t>(p, p + n), clock.now});
                   return true;
                 },
                 &stats, nullptr, clock);
    ASSERT_EQ(out.size(), 104u);
    EXPECT_EQ(stats.published, 104);
    EXPECT_NEAR(stats.log_s(), 0.99, 1e-9);
    int k = 0;
    for (const auto& p : out) {
      if (p.channel == "BALL_BOX") {
        EXPECT_EQ(p.data, Box(k++));  // same bytes, same order
      }
    }
    EXPECT_EQ(k, 100);
    // Each event is released at its logged offset / speed.
    const int64_t expect_last = speed > 0 ? 777 + std::llround(990000 / speed) : 777;
    EXPECT_EQ(out.back().at, expect_last) << speed;
    EXPECT_EQ(out[2].at, speed > 0 ? 777 + std::llround(10000 / speed) : 777);
  }
}

TEST(LogReplay, FiltersChannelsByRegex) {
  const auto dir = testing::ScratchDir("lcm_log_filter");
  const std::string log = WriteLog(dir);
  LogReplayConfig c;
  c.speed = 0;
  c.channels_regex = "CALIB.*";
  std::vector<std::string> channels;
  LogReplayStats stats;
  ReplayLcmLog(log, c,
               [&](const std::string& ch, const void*, std::size_t) {
                 channels.push_back(ch);
                 return true;
               },
               &stats);
  EXPECT_EQ(channels, std::vector<std::string>(4, "CALIBRATION"));
  EXPECT_EQ(stats.events, 104);
  c.channels_regex = "BALL_(";
  EXPECT_THROW(ReplayLcmLog(log, c, PublishFn(), &stats), std::invalid_argument);
}

TEST(LogReplay, RepublishesOnARealBus) {
  const auto dir = testing::ScratchDir("lcm_log_bus");
  const std::string log = WriteLog(dir);
  LcmBus bus("memq://");
  std::vector<int64_t> frames;
  bus.Subscribe<ball_box_t>("BALL_BOX", [&](const ball_box_t& m) { frames.push_back(m.frame); });
  LogReplayConfig c;
  c.speed = 0;
  LogReplayStats stats;
  ReplayLcmLog(log, c, PublishOn(bus), &stats);
  while (bus.HandleOnce(0)) {
  }
  ASSERT_EQ(frames.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(frames[i], i);
}

std::string ErrorOf(const std::string& path, int64_t* published = nullptr) {
  LogReplayStats stats;
  LogReplayConfig c;
  c.speed = 0;
  try {
    ReplayLcmLog(path, c, [](const std::string&, const void*, std::size_t) { return true; },
                 &stats);
  } catch (const std::runtime_error& e) {
    if (published) *published = stats.published;
    return e.what();
  }
  return "";
}

TEST(LogReplay, CorruptLogsAreOneLineErrorsAfterTheGoodPart) {
  const auto dir = testing::ScratchDir("lcm_log_corrupt");
  const std::string bytes = testing::ReadFile(WriteLog(dir));
  const auto write = [&](const std::string& name, const std::string& content) {
    const std::string p = (dir / name).string();
    std::ofstream(p, std::ios::binary) << content;
    return p;
  };
  EXPECT_EQ(ErrorOf((dir / "none.lcm").string()),
            "cannot open LCM log '" + (dir / "none.lcm").string() + "': no such file");
  const std::string video = write("video.lcm", "RIFF....AVI LIST");
  EXPECT_EQ(ErrorOf(video), "'" + video + "' is not an LCM log (no event header at its start)");

  // Cut in the middle of an event: every whole event before it is still republished.
  int64_t published = -1;
  const std::string cut = write("cut.lcm", bytes.substr(0, bytes.size() / 2 + 7));
  const std::string e1 = ErrorOf(cut, &published);
  EXPECT_NE(e1.find("corrupt LCM log '" + cut + "': truncated event"), std::string::npos) << e1;
  EXPECT_GT(published, 45);
  EXPECT_LT(published, 55);

  // Garbage over the 11th event's header (LCM's own reader would skip to the next event).
  std::string garbled = bytes;
  std::size_t at = 0;
  for (int k = 0; k < 11; ++k) at = garbled.find("\xED\xA1\xDA\x01", k ? at + 1 : 0);
  ASSERT_NE(at, std::string::npos);
  for (std::size_t i = 0; i < 8; ++i) garbled[at + i] = 'G';
  const std::string g = write("garbled.lcm", garbled);
  const std::string e2 = ErrorOf(g, &published);
  EXPECT_NE(e2.find("corrupt LCM log '" + g + "'"), std::string::npos) << e2;
  EXPECT_EQ(e2.find('\n'), std::string::npos);
  EXPECT_GE(published, 9);
  EXPECT_LE(published, 11);

  // An empty log is a log with no events, not an error.
  EXPECT_EQ(ErrorOf(write("empty.lcm", "")), "");
}

TEST(ReplayLogCommand, CorruptLogOrBadFlagIsOneLineAndNonZero) {
  const auto dir = testing::ScratchDir("replay_log_cli");
  const std::string log = (dir / "x.lcm").string();
  std::ofstream(log) << "not a log at all";
  std::string out;
  EXPECT_EQ(testing::RunCommand(testing::BouncefitExe() + " replay-log '" + log + "'", &out), 1);
  EXPECT_EQ(out, "bouncefit replay-log: error: '" + log +
                     "' is not an LCM log (no event header at its start)\n");
  EXPECT_EQ(testing::RunCommand(testing::BouncefitExe() + " replay-log '" + log + "' --speed -1", &out), 2);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
}

}  // namespace
}  // namespace bouncefit
