// FitSession, FitWorker (supersede, never queue), the searches on the point-mass model, the
// fit node over real LCM (memq://), the exports and the offline CLI.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "fit/fit_export.h"
#include "fit/fit_session.h"
#include "fit/fit_worker.h"
#include "fit/nlopt_search.h"
#include "fit/paper_search.h"
#include "model/ball_preset.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"
#include "msgs/lcm_bus.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

using namespace std::chrono_literals;
using testing::DropHeights;

// The point mass, slowed down and counting: a stand-in for an expensive simulator whose
// timing the test controls.
class SlowModel : public BallModel {
 public:
  SlowModel(const BallPreset& ball, std::chrono::milliseconds delay) : inner_(ball), delay_(delay) {}
  std::string name() const override { return "slow-point-mass"; }
  std::vector<CoefficientSpec> Coefficients() const override { return inner_.Coefficients(); }
  SimulationResult Simulate(const CoefficientValues& v, const SimulationOptions& o) const override {
    ++started;
    std::this_thread::sleep_for(delay_);
    return inner_.Simulate(v, o);
  }
  mutable std::atomic<int> started{0};

 private:
  PointMassModel inner_;
  std::chrono::milliseconds delay_;
};

struct Collected {
  std::mutex mutex;
  std::vector<FitUpdate> updates;
  void Add(const FitUpdate& u) {
    std::lock_guard<std::mutex> lock(mutex);
    updates.push_back(u);
  }
  std::vector<FitUpdate> Get() {
    std::lock_guard<std::mutex> lock(mutex);
    return updates;
  }
};

template <class Pred>
bool WaitFor(Pred pred, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(2ms);
  }
  return true;
}

TEST(FitWorker, NewerBounceSupersedesTheRunningUpdateNeverQueues) {
  const auto ball = *FindBallPreset("tennis");
  SlowModel slow(ball, 40ms);
  PointMassModel quick(ball);
  FitSessionConfig cfg;
  cfg.max_evaluations_per_bounce = 30;  // 30 x 40 ms: far longer than the test waits
  cfg.max_evaluations_final = 12;
  cfg.threads = 2;
  Collected got;
  FitWorker worker(std::make_unique<FitSession>(slow, &quick, cfg),
                   [&](const FitUpdate& u) { got.Add(u); });
  worker.Start();
  const auto h = DropHeights(ball, 1.0, 3);
  worker.Submit({0, 0, h[0], 0.001, 0});
  worker.Submit({0, 1, h[1], 0.001, 1000});
  ASSERT_TRUE(WaitFor([&] { return slow.started.load() >= 2; }, 5s));
  // Bounce 2 arrives while bounce 1's update runs: it is cut short between simulations.
  const auto t_cancel = std::chrono::steady_clock::now();
  worker.Submit({0, 2, h[2], 0.001, 2000});
  ASSERT_TRUE(WaitFor([&] {
    for (const auto& u : got.Get())
      if (u.model == "slow-point-mass" && u.after_bounce == 2) return true;
    return false;
  }, 10s));
  worker.Finish();
  worker.WaitIdle();
  const double to_update2 =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_cancel).count();

  std::vector<int> slow_after, quick_after;
  int finals = 0;
  for (const auto& u : got.Get()) {
    if (u.final) {
      ++finals;
      EXPECT_EQ(u.after_bounce, 2);
      EXPECT_EQ(u.model, "slow-point-mass");
      continue;
    }
    (u.model == "point-mass" ? quick_after : slow_after).push_back(u.after_bounce);
  }
  // Bounce 1's model update was superseded, not delivered late; bounce 2's was delivered.
  EXPECT_EQ(slow_after, std::vector<int>{2});
  EXPECT_EQ(quick_after, (std::vector<int>{1, 2}));  // the quick fit is out at once
  EXPECT_EQ(finals, 1);
  const auto s = worker.stats();
  EXPECT_EQ(s.superseded, 1);
  EXPECT_EQ(s.peaks, 3);
  // The cancelled update did not run its budget out: the whole thing (cancel, update 2 and
  // the final) took far less than 30 simulations of 40 ms.
  EXPECT_LT(to_update2, 30 * 0.040 + 12 * 0.040);
}

// The end of a stream asks for the final fit twice (the drop ends, then the stream): the
// second Finish() must not cut the running final fit short (it once ran 6 of 160 sims).
TEST(FitWorker, SecondFinishLetsTheRunningFinalFitEnd) {
  const auto ball = *FindBallPreset("tennis");
  SlowModel slow(ball, 10ms);
  FitSessionConfig cfg;
  cfg.max_evaluations_per_bounce = 4;
  cfg.max_evaluations_final = 40;
  cfg.threads = 2;
  cfg.quick_fit = false;
  Collected got;
  FitWorker worker(std::make_unique<FitSession>(slow, nullptr, cfg),
                   [&](const FitUpdate& u) { got.Add(u); });
  worker.Start();
  const auto h = DropHeights(ball, 1.0, 3);
  for (int b = 0; b <= 3; ++b) worker.Submit({0, b, h[b], 0.001, b});
  worker.WaitIdle();
  const int before_final = slow.started.load();
  worker.Finish();
  ASSERT_TRUE(WaitFor([&] { return slow.started.load() >= before_final + 3; }, 5s));
  worker.Finish();  // the stream's end, while the final fit runs
  worker.WaitIdle();
  int finals = 0;
  for (const auto& u : got.Get())
    if (u.final) {
      ++finals;
      EXPECT_FALSE(u.cancelled);
      EXPECT_GT(u.evaluations, 10) << "the final fit was cut short";
    }
  EXPECT_EQ(finals, 1);
}

TEST(FitWorker, NewSequenceFinalisesThePreviousDrop) {
  const auto ball = *FindBallPreset("wiffle");
  PointMassModel model(ball);
  FitSessionConfig cfg;
  cfg.max_evaluations_per_bounce = 10;
  cfg.max_evaluations_final = 20;
  Collected got;
  FitWorker worker(std::make_unique<FitSession>(model, &model, cfg),
                   [&](const FitUpdate& u) { got.Add(u); });
  worker.Start();
  const auto h = DropHeights(ball, 1.2, 2);
  for (int b = 0; b <= 2; ++b) worker.Submit({0, b, h[b], 0.001, b});
  worker.WaitIdle();
  worker.Submit({1, 0, 1.0, 0.001, 10});
  worker.WaitIdle();
  int finals = 0;
  for (const auto& u : got.Get())
    if (u.final) {
      ++finals;
      EXPECT_EQ(u.sequence, 0);
      EXPECT_EQ(u.after_bounce, 2);
    }
  EXPECT_EQ(finals, 1);
}

// The ball dropped again in the same stream: the second drop's final fit
// takes the first drop's bounces too, each drop from its own height.
TEST(FitWorker, AStreamsLaterDropIsFittedWithTheEarlierOnes) {
  const auto ball = *FindBallPreset("wiffle");
  PointMassModel model(ball);
  FitSessionConfig cfg;
  cfg.max_evaluations_per_bounce = 10;
  cfg.max_evaluations_final = 40;
  Collected got;
  FitWorker worker(std::make_unique<FitSession>(model, &model, cfg),
                   [&](const FitUpdate& u) { got.Add(u); });
  worker.Start();
  const auto first = DropHeights(ball, 1.2, 2), second = DropHeights(ball, 0.8, 2);
  for (int b = 0; b <= 2; ++b) worker.Submit({0, b, first[b], 0.001, b});
  worker.WaitIdle();
  for (int b = 0; b <= 2; ++b) worker.Submit({1, b, second[b], 0.001, 10 + b});
  worker.Finish();
  worker.WaitIdle();
  std::vector<FitUpdate> finals;
  for (const auto& u : got.Get())
    if (u.final) finals.push_back(u);
  ASSERT_EQ(finals.size(), 2u);
  EXPECT_TRUE(finals[0].other_drop_heights_m.empty());
  const FitUpdate& joint = finals[1];
  EXPECT_EQ(joint.sequence, 1);
  EXPECT_DOUBLE_EQ(joint.drop_height_m, 0.8);
  EXPECT_EQ(joint.other_drop_heights_m, std::vector<double>{1.2});
  EXPECT_EQ(joint.other_drop_bounces, std::vector<int>{2});
  ASSERT_EQ(joint.recorded_m.size(), 4u);
  const std::vector<double> want = {second[1], second[2], first[1], first[2]};
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_DOUBLE_EQ(joint.recorded_m[i], want[i]);
    EXPECT_NEAR(joint.simulated_m[i], want[i], 0.002) << i;  // the truth's own model
  }
}

// Warm start and per-bounce refinement on a model with known truth: each update matches the
// bounces it has, and the final fit recovers the restitution.
TEST(FitSession, PerBounceUpdatesFollowTheDropAndTheFinalRecoversTruth) {
  auto truth = *FindBallPreset("softball");
  truth.restitution = 0.50;  // preset 0.42: the fit has to move
  const auto h = DropHeights(truth, 1.2, 5);
  PointMassModel model(*FindBallPreset("softball"));
  FitSessionConfig cfg;
  cfg.max_evaluations_per_bounce = 20;
  cfg.max_evaluations_final = 150;
  cfg.final_starts = 1;  // a smooth model: one search gets there, no need for several draws
  FitSession s(model, nullptr, cfg);
  s.AddPeak({0, 0, h[0], 0.001, 0});
  for (int k = 1; k < static_cast<int>(h.size()); ++k) {
    if (h[k] < 0.01) break;
    s.AddPeak({0, k, h[k], 0.001, k});
    const FitUpdate u = s.Update();
    EXPECT_EQ(u.after_bounce, k);
    EXPECT_EQ(u.model, "point-mass");
    EXPECT_FALSE(u.final);
    EXPECT_LE(u.evaluations, 20);
    EXPECT_LT(u.residual_m, 0.01 * h[0]) << "after bounce " << k;
  }
  const FitUpdate f = s.FinalUpdate();
  EXPECT_TRUE(f.final);
  EXPECT_LT(f.residual_m, 0.001 * h[0]);
  EXPECT_NEAR(f.values.at("restitution"), 0.50, 0.02);
}

// Same inputs, both searches: the default reaches the paper search's residual with far
// fewer simulations (the soft-body version of this is bench/fit_bench.cc).
TEST(Searches, DefaultReachesPaperResidualWithFewerSimulations) {
  auto truth = *FindBallPreset("airball");
  truth.restitution = 0.72;
  truth.drag_coefficient = 0.9;
  const auto h = DropHeights(truth, 1.5, 6);
  PointMassModel model(*FindBallPreset("airball"));
  FitProblem p;
  p.model = &model;
  p.free = model.Coefficients();
  p.recorded_m.assign(h.begin() + 1, h.end());
  p.simulation.drop_height_m = h[0];
  p.simulation.duration_s = 8;
  p.simulation.min_bounce_height_m = 0.005;
  SearchOptions o;
  o.max_evaluations = 400;
  const SearchResult paper = PaperSearch(p, {}, o);
  // A smooth model takes BOBYQA's small trust radius; the default (0.15) suits the noisy
  // camera-rate heights of the soft body.
  NloptSearchOptions smooth;
  smooth.initial_step = 0.05;
  const SearchResult fast = NloptSearch(p, {}, o, smooth);
  EXPECT_EQ(paper.method, "paper");
  EXPECT_EQ(fast.method, "nlopt-bobyqa");
  EXPECT_GT(paper.evaluations, 10);
  EXPECT_LT(paper.rms_m, 0.01);
  // Simulations the default needed to get at or below the paper's final objective.
  int reached = -1;
  for (size_t i = 0; i < fast.best_history.size(); ++i)
    if (fast.best_history[i] <= paper.objective) {
      reached = static_cast<int>(i) + 1;
      break;
    }
  ASSERT_GT(reached, 0) << "default search never reached the paper's residual " << paper.rms_m;
  EXPECT_LE(3 * reached, paper.evaluations)
      << "default " << reached << " vs paper " << paper.evaluations;
}

// Multiple shooting: every bounce simulated from the recorded apex before it. At the true
// coefficients each segment lands on its recorded apex; a wrong restitution misses every one
// by about the same fraction (errors do not compound from bounce to bounce).
TEST(Searches, SegmentsStartFromTheRecordedApexes) {
  const BallPreset ball = *FindBallPreset("tennis");
  const auto h = DropHeights(ball, 1.0, 5);
  PointMassModel model(ball);
  FitProblem p;
  p.model = &model;
  p.free = {model.Coefficients()[0]};  // restitution
  p.simulation.drop_height_m = h[0];
  p.simulation.duration_s = 6;
  p.recorded_m.assign(h.begin() + 1, h.end());
  p.segments = true;
  SearchOptions o;
  o.threads = 2;
  FitObjective f(p, o);
  const Evaluation at_truth = f.Evaluate(f.ToUnit({{"restitution", ball.restitution}}));
  ASSERT_TRUE(at_truth.ok) << at_truth.failure;
  for (size_t i = 0; i < p.recorded_m.size(); ++i)
    EXPECT_NEAR(at_truth.simulated_m[i], p.recorded_m[i], 1e-3 * p.recorded_m[i]) << i;
  const Evaluation off = f.Evaluate(f.ToUnit({{"restitution", ball.restitution - 0.05}}));
  ASSERT_TRUE(off.ok) << off.failure;
  std::vector<double> ratio;
  for (size_t i = 0; i < p.recorded_m.size(); ++i) ratio.push_back(off.simulated_m[i] / p.recorded_m[i]);
  EXPECT_LT(ratio[0], 0.95);
  // Free running, the 5th bounce would be ~0.87^5 of the truth; a segment is one step off.
  EXPECT_NEAR(ratio.back(), ratio.front(), 0.03);
  EXPECT_EQ(f.evaluations(), 2);
}

TEST(Searches, CancelledBetweenSimulations) {
  const auto ball = *FindBallPreset("pingpong");
  SlowModel slow(ball, 20ms);
  FitProblem p;
  p.model = &slow;
  p.free = slow.Coefficients();
  p.recorded_m = {0.7, 0.5};
  p.simulation.drop_height_m = 1.0;
  p.simulation.duration_s = 3;
  CancelToken token;
  SearchOptions o;
  o.max_evaluations = 1000;
  o.cancel = &token;
  o.threads = 1;
  std::thread canceller([&] {
    WaitFor([&] { return slow.started.load() >= 3; }, 5s);
    token.Cancel();
  });
  const SearchResult r = PaperSearch(p, {}, o);
  canceller.join();
  EXPECT_TRUE(r.cancelled);
  EXPECT_LE(r.evaluations, 4);  // the one running when cancelled finishes, no more start
}

TEST(FitExport, JsonAndAFittedBallProjectWithEveryValue) {
  FitUpdate u;
  u.model = "bullet-softbody";
  u.method = "nlopt-bobyqa";
  u.final = true;
  u.time_step_s = 1.0 / 960;
  u.iterations = 4;
  u.drop_height_m = 1.0;
  u.values = {{"linear_stiffness", 0.8}, {"pressure", 2.0}, {"damping", 0.01},
              {"rebound_boost", 0.2}, {"mesh_resolution", 3}};
  CoefficientEstimate e;
  e.name = "linear_stiffness";
  e.value = 0.8;
  e.sigma = 0.02;
  e.identifiable = true;
  u.coefficients = {e};
  u.recorded_m = {0.8};
  u.simulated_m = {0.79};
  u.residual_m = 0.01;
  const auto ball = *FindBallPreset("pingpong");
  const auto dir = testing::ScratchDir("fit_export");
  const auto paths = WriteFitExports(dir, u, ball);
  ASSERT_EQ(paths.size(), 3u);
  EXPECT_EQ(paths[1], dir / "fitted_ball.glb");
  EXPECT_EQ(paths[2], dir / "fitted_ball");
  std::ifstream in(paths[0]);
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["coefficients"]["linear_stiffness"]["value"], 0.8);
  EXPECT_EQ(j["time_step_s"], 1.0 / 960);
  EXPECT_EQ(j["iterations"], 4);
  EXPECT_EQ(j["ball"]["name"], "pingpong");
  // The project's data: the fit's step and every coefficient, defaults filled in
  // (tests/fit_export_project_slow_test.cc builds and runs it).
  std::ifstream data_in(dir / "fitted_ball" / "fitted_ball_data.cc");
  std::stringstream data;
  data << data_in.rdbuf();
  EXPECT_NE(data.str().find("config.time_step_s = 0.0010416666666666667;"), std::string::npos);
  EXPECT_NE(data.str().find("{\"pressure\", 2}"), std::string::npos) << data.str().substr(0, 400);
  EXPECT_NE(data.str().find("{\"angular_stiffness\", 1}"), std::string::npos);
  for (const char* f : {"CMakeLists.txt", "main.cc", "fitted_ball.h", "model/soft_ball_world.cc"})
    EXPECT_TRUE(std::filesystem::exists(dir / "fitted_ball" / f)) << f;
  // Exported again over an older export: a model file it does not ship is gone (the
  // project globs model/*.cc).
  std::ofstream(dir / "fitted_ball" / "model" / "stale.cc") << "#error stale\n";
  WriteFitExports(dir, u, ball);
  EXPECT_FALSE(std::filesystem::exists(dir / "fitted_ball" / "model" / "stale.cc"));
  EXPECT_TRUE(std::filesystem::exists(dir / "fitted_ball" / "model" / "soft_ball_world.cc"));
}

TEST(FitCli, OfflineHeightsPrintUpdatesAndWriteExports) {
  const auto dir = testing::ScratchDir("fit_cli");
  std::string out;
  const int rc = testing::RunCommand(
      testing::BouncefitExe() +
          " fit --heights 1.0,0.62,0.40,0.26 --ball tennis --model point-mass --max-evals 60"
          " --export '" + dir.string() + "'",
      &out);
  ASSERT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("FINAL fit after bounce 3"), std::string::npos) << out;
  EXPECT_NE(out.find("restitution"), std::string::npos);
  EXPECT_NE(out.find("mm over 3 bounces"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "coefficients.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "fitted_ball" / "README.md"));  // nothing to build
  // Bad input is a one-line error.
  const int bad = testing::RunCommand(testing::BouncefitExe() + " fit --heights 1.0,abc", &out);
  EXPECT_EQ(bad, 2);  // a bad flag
  EXPECT_NE(out.find("bouncefit fit: error:"), std::string::npos) << out;
}

}  // namespace
}  // namespace bouncefit
