// What `run` prints for the bounces: the peaks as they go out, then the final rows. The
// messages are those of a real run (izhan_ball.mp4, a 30 fps ping-pong clip of
// scripts/real_runs/get_other_clips.sh): its picture found the ball after the first rebound,
// saw the second rebound higher than the first, and the sound, heard from the first impact,
// numbered every row one up.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/drop_t.hpp"
#include "cli/run_console.h"

namespace bouncefit {
namespace {

using cli::ConsoleMode;
using cli::RunConsole;

int64_t Us(double s) { return std::llround(s * 1e6); }

// The live peaks (bounce, apex time s, height m) the run emitted.
struct Live {
  int bounce;
  double t_s, height_m;
};
const std::vector<Live> kLive = {{1, 0.769, 0.0762},  {2, 1.037, 0.0821},  {3, 1.296, 0.0777},  {4, 1.532, 0.0629},
                                 {5, 1.757, 0.0582},  {6, 1.970, 0.0497},  {7, 2.172, 0.0447},  {8, 2.359, 0.0380},
                                 {9, 2.526, 0.0308},  {10, 2.689, 0.0286}, {11, 2.842, 0.0262}};

bounce_peak_t Peak(int bounce, double t_s, double height_m) {
  bounce_peak_t m{};
  m.bounce = m.live_bounce = bounce;
  m.apex_utime = Us(t_s);
  m.emitted_utime = m.utime = Us(t_s + 0.05);
  m.height_m = m.fused_height_m = height_m;
  m.flight_height_m = m.refit_height_m = NAN;
  return m;
}

// Its final row: live bounce `live` (-1: heard only) as bounce `bounce`.
bounce_peak_t Row(int live, int bounce, double t_s, double height_m) {
  bounce_peak_t m = Peak(bounce, t_s, height_m);
  m.live_bounce = live;
  m.revision = 3;
  m.heard = live < 0 ? "heard only" : "both";
  return m;
}

bounce_peak_t Withdrawn(int live, double t_s, double height_m) {
  bounce_peak_t m = Peak(live, t_s, height_m);
  m.revision = 4;
  return m;
}

drop_t Done() {
  drop_t d{};
  d.state = "done";
  return d;
}

// The console's lines for these messages (the drop's "done" after them, if `done`).
std::vector<std::string> Print(ConsoleMode mode, const std::vector<bounce_peak_t>& messages, bool done = true) {
  char* buf = nullptr;
  size_t size = 0;
  std::FILE* out = open_memstream(&buf, &size);
  {
    RunConsole console(mode, out);
    stream_t start{};
    start.state = "start";
    console.OnStream(start);
    for (const auto& m : messages) console.OnPeak(m);
    if (done) console.OnDrop(Done());
  }
  std::fclose(out);
  std::vector<std::string> lines;
  std::istringstream text(std::string(buf, size));
  std::free(buf);
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  return lines;
}

std::vector<bounce_peak_t> LivePeaks() {
  std::vector<bounce_peak_t> out;
  for (const Live& p : kLive) out.push_back(Peak(p.bounce, p.t_s, p.height_m));
  return out;
}

int Count(const std::vector<std::string>& lines, const std::string& part) {
  int n = 0;
  for (const auto& l : lines) n += l.find(part) != std::string::npos;
  return n;
}

TEST(RunConsole, AReboundHigherThanTheApexBeforeIsSaidSuspect) {
  const auto lines = Print(ConsoleMode::kHuman, LivePeaks());
  ASSERT_EQ(lines.size(), kLive.size());
  EXPECT_NE(lines[1].find("e=1.038 (higher than the apex before: suspect)"), std::string::npos) << lines[1];
  // Every e above 1 says so; none at or below 1 does.
  for (const auto& l : lines) {
    const auto at = l.find("e=");
    if (at == std::string::npos) continue;
    const double e = std::stod(l.substr(at + 2));
    EXPECT_EQ(e > 1, l.find("suspect") != std::string::npos) << l;
  }
  const auto json = Print(ConsoleMode::kJson, LivePeaks());
  ASSERT_EQ(json.size(), kLive.size());
  const auto second = nlohmann::json::parse(json[1]);
  EXPECT_NEAR(second["e"].get<double>(), 1.038, 0.001);
  EXPECT_EQ(second["suspect"], "higher than the apex before");
  EXPECT_FALSE(nlohmann::json::parse(json[2]).contains("suspect"));
}

TEST(RunConsole, ABounceHeardBeforeTheFirstSeenRenumbersInOneLine) {
  std::vector<bounce_peak_t> messages = LivePeaks();
  messages.push_back(Row(-1, 1, 0.483, 0.1117));
  for (const Live& p : kLive) messages.push_back(Row(p.bounce, p.bounce + 1, p.t_s, p.height_m));
  messages.push_back(Row(-1, 13, 2.997, 0.0242));
  const auto lines = Print(ConsoleMode::kHuman, messages);
  const std::vector<std::string> final_lines(lines.begin() + static_cast<long>(kLive.size()), lines.end());
  ASSERT_EQ(final_lines.size(), 3u) << ::testing::PrintToString(lines);
  EXPECT_EQ(final_lines[0], "renumbered: #1-#11 are #2-#12 (a bounce heard before the first one seen)");
  EXPECT_NE(final_lines[1].find("peak  #1 "), std::string::npos) << final_lines[1];
  EXPECT_NE(final_lines[1].find("heard only"), std::string::npos) << final_lines[1];
  EXPECT_NE(final_lines[2].find("peak  #13"), std::string::npos) << final_lines[2];
  EXPECT_EQ(Count(lines, "is bounce"), 0);
  // No DROP "done" (the detect node gone): the rows are said all the same, at the end.
  EXPECT_EQ(Print(ConsoleMode::kHuman, messages, false), lines);
}

// The picture split one heard arc in two (live #3, withdrawn) after a bounce heard first: the
// rows before the split move up by one, those after it keep their numbers. Only the rows that
// moved are said, as one line for the run of them.
TEST(RunConsole, RowsThatKeepTheirNumbersAreNotSaid) {
  std::vector<bounce_peak_t> messages = LivePeaks();
  messages.push_back(Withdrawn(3, 1.296, 0.0777));
  messages.push_back(Row(-1, 1, 0.483, 0.1117));
  for (const Live& p : kLive)
    if (p.bounce != 3) messages.push_back(Row(p.bounce, p.bounce < 3 ? p.bounce + 1 : p.bounce, p.t_s, p.height_m));
  const auto lines = Print(ConsoleMode::kHuman, messages);
  EXPECT_EQ(Count(lines, "revised #3: withdrawn"), 1);
  EXPECT_EQ(Count(lines, "renumbered: #1-#2 are #2-#3 (a bounce heard before the first one seen)"), 1)
      << ::testing::PrintToString(lines);
  EXPECT_EQ(Count(lines, "renumbered:"), 1);
  EXPECT_EQ(Count(lines, "is bounce"), 0);

  // Split at live #2 instead: live #1 alone moves, and is said on its own line.
  messages = LivePeaks();
  messages.push_back(Withdrawn(2, 1.037, 0.0821));
  messages.push_back(Row(-1, 1, 0.483, 0.1117));
  for (const Live& p : kLive)
    if (p.bounce != 2) messages.push_back(Row(p.bounce, p.bounce < 2 ? p.bounce + 1 : p.bounce, p.t_s, p.height_m));
  const auto alone = Print(ConsoleMode::kHuman, messages);
  EXPECT_EQ(Count(alone, "revised #1: is bounce 2"), 1) << ::testing::PrintToString(alone);
  EXPECT_EQ(Count(alone, "renumbered:"), 0);
}

}  // namespace
}  // namespace bouncefit
