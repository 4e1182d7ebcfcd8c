// A 1 m ping-pong drop replayed in real time through `run`: the soft-body update for each
// of the first five bounces goes out before the next apex arrives. Wall-clock deadlines:
// label realtime, run alone.
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/test_support.h"

namespace bouncefit {
namespace {

using testing::BouncefitExe;
using testing::RunCommand;

TEST(RunLiveFit, SoftBodyUpdateForEachOfTheFirstFiveBouncesBeforeTheNextApex) {
  const auto dir = testing::ScratchDir("live_fit");
  const auto clip = dir / "pingpong.avi";
  std::string out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " synth --quiet --ball pingpong --drop-height 1.0 "
                                        "--duration 4.5 --noise 3 --seed 11 --out " +
                           clip.string(),
                       &out),
            0)
      << out;
  ASSERT_EQ(RunCommand(BouncefitExe() + " run " + clip.string() + " --out " +
                           (dir / "out").string() + " --lcm-url memq:// --json",
                       &out),
            0)
      << out;

  std::map<int, double> apex_t, emitted_t;      // bounce -> stream time, s
  std::map<int, double> update_t;               // after_bounce -> publication time, s
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded()) continue;
    const std::string event = j.value("event", "");
    if (event == "peak") {
      apex_t[j["bounce"]] = j["t_s"];
      emitted_t[j["bounce"]] = j["emitted_t_s"];
    } else if (event == "fit" && j["model"] == "bullet-softbody" && !j["final"].get<bool>()) {
      update_t[j["after_bounce"]] = j["published_t_s"];
    }
  }
  for (int k = 1; k <= 5; ++k) {
    ASSERT_TRUE(update_t.count(k)) << "no soft-body update for bounce " << k << "\n" << out;
    ASSERT_TRUE(emitted_t.count(k + 1)) << "bounce " << k + 1 << " not detected";
    EXPECT_LT(update_t[k], emitted_t[k + 1])
        << "update for bounce " << k << " at " << update_t[k] << " s, apex " << k + 1
        << " emitted at " << emitted_t[k + 1] << " s";
    EXPECT_GT(update_t[k], apex_t[k]);
  }
}

}  // namespace
}  // namespace bouncefit
