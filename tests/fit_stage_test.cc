// The fit stage (pipeline/fit_stage.h) over real LCM traffic (memq://): BOUNCE_PEAK and DROP
// in; FIT_UPDATE out after every bounce and at the drop's end; fit.jsonl, coefficients.json
// and simulated.csv written once the stream is done.
#include "pipeline/fit_stage.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <string>
#include <thread>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/drop_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "model/ball_preset.h"
#include "msgs/lcm_bus.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using namespace std::chrono_literals;
using testing::DropHeights;

// Dispatches and polls until the stage's worker has nothing left to fit.
void Settle(LcmBus& bus, FitStage& stage) {
  const auto until = std::chrono::steady_clock::now() + 20s;
  do {
    bus.Drain();
    stage.Poll();
    std::this_thread::sleep_for(2ms);
  } while (stage.busy() && std::chrono::steady_clock::now() < until);
  bus.Drain();
  stage.Poll();
  bus.Drain();
}

TEST(FitStage, PeaksInUpdatesAndFilesOut) {
  const auto dir = testing::ScratchDir("out");
  LcmBus bus("memq://");
  std::vector<fit_update_t> received;
  bus.Subscribe<fit_update_t>("FIT_UPDATE", [&](const fit_update_t& m) { received.push_back(m); });
  FitStageConfig cfg;
  cfg.fit.ball = ResolveBallPreset("tennis");
  cfg.fit.model = "point-mass";
  cfg.fit.session.max_evaluations_per_bounce = 10;
  cfg.fit.session.max_evaluations_final = 30;
  cfg.out_dir = dir;
  FitStage stage(cfg, bus);
  const auto h = DropHeights(stage.ball(), 1.0, 3);
  for (int b = 0; b <= 3; ++b) {
    bounce_peak_t p{};
    p.utime = 1000000 + b * 700000;
    p.sequence = 0;
    p.bounce = b;
    p.live_bounce = b;
    p.apex_utime = p.utime - 50000;
    p.height_m = h[b];
    p.height_sigma_m = 0.002;
    p.flight_height_m = p.refit_height_m = p.fused_height_m = NAN;
    bus.Publish("BOUNCE_PEAK", p);
    Settle(bus, stage);  // offline pacing: each bounce fitted before the next
  }
  drop_t done{};
  done.utime = 4000000;
  done.state = "done";
  done.reason = "end of stream";
  done.stream_start_utime = 0;
  bus.Publish("DROP", done);
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (!stage.done() && std::chrono::steady_clock::now() < until) Settle(bus, stage);
  ASSERT_TRUE(stage.done());

  // Bounces 1-3: a quick and a model update each, then the final fit.
  ASSERT_EQ(received.size(), 7u);
  EXPECT_TRUE(received.back().final);
  EXPECT_EQ(received.back().after_bounce, 3);
  EXPECT_EQ(received[0].after_bounce, 1);
  EXPECT_EQ(received[0].model, "point-mass");
  EXPECT_EQ(received[0].method, "least-squares");
  for (const auto& m : received) {
    EXPECT_EQ(m.num_coeffs, static_cast<int>(m.names.size()));
    EXPECT_EQ(m.num_bounces, m.after_bounce);
    EXPECT_GT(m.evaluations, 0);
    EXPECT_EQ(m.utime, 1000000 + m.after_bounce * 700000);
  }
  const auto& f = received.back();
  EXPECT_LT(f.residual_m, 0.003);
  for (int i = 0; i < f.num_bounces; ++i) EXPECT_NEAR(f.recorded_m[i], h[i + 1], 1e-12);
  EXPECT_EQ(bus.handler_failures(), 0);
  ASSERT_TRUE(stage.final_fit().has_value());
  EXPECT_EQ(stage.no_fit_why(), "");

  // fit.jsonl: a line per update published; the final fit's files.
  std::ifstream jsonl(dir / "fit.jsonl");
  int lines = 0;
  for (std::string line; std::getline(jsonl, line);) ++lines;
  EXPECT_EQ(lines, 7);
  EXPECT_TRUE(std::filesystem::exists(dir / "coefficients.json"));
  const auto simulated = testing::ReadCsv(dir / "simulated.csv");
  ASSERT_FALSE(simulated.empty());
  EXPECT_NEAR(std::stod(simulated.front().at("height_m")), 1.0, 0.05);  // from the drop's start apex
}

}  // namespace
}  // namespace bouncefit
