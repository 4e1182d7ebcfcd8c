// The fitter keeps up with a live drop: live updates of a ping-pong drop replayed on the
// wall clock come out before the next apex. Its deadlines are wall-clock ones, so it runs
// alone (label realtime: ctest runs it serially).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <thread>

#include "fit/fit_models.h"
#include "fit/fit_session.h"
#include "fit/fit_worker.h"
#include "model/ball_preset.h"
#include "model/model_by_name.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"
#include "tests/point_mass_truth.h"

namespace bouncefit {
namespace {

TEST(LiveFit, FirstFiveUpdatesBeforeTheNextApex) {
  const BallPreset ball = ResolveBallPreset("pingpong");
  const auto truth = testing::PointMassTruth(ball, 1.0);
  auto model = MakeBallModel("bullet-softbody", ball);
  PointMassModel quick(ball);
  FitSessionConfig cfg;
  ConfigureSessionForModel(*model, ball, &cfg);
  using Clock = std::chrono::steady_clock;
  std::mutex m;
  std::map<int, double> at;
  Clock::time_point t0;
  FitWorker worker(std::make_unique<FitSession>(*model, &quick, cfg), [&](const FitUpdate& u) {
    if (u.model != "bullet-softbody" || u.final) return;
    std::lock_guard<std::mutex> lock(m);
    at[u.after_bounce] = std::chrono::duration<double>(Clock::now() - t0).count();
  });
  worker.Start();
  const double release = truth.release_time_s;
  t0 = Clock::now();
  for (int b = 0; b <= 6; ++b) {
    const double emit = b == 0 ? 0.0 : truth.apex_times_s[b] - release + 0.05;
    std::this_thread::sleep_until(t0 + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(emit)));
    worker.Submit({0, b, truth.apex_heights_m[b], 0.001, 0});
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  worker.Stop();
  std::lock_guard<std::mutex> lock(m);
  for (int b = 1; b <= 5; ++b) {
    ASSERT_TRUE(at.count(b)) << "bounce " << b << " update superseded";
    const double apex = truth.apex_times_s[b] - release;
    const double next = truth.apex_times_s[b + 1] - release;
    std::printf("bounce %d: apex %.3f s, update %.3f s (apex->update %.3f s), next apex %.3f s\n",
                b, apex, at[b], at[b] - apex, next);
    EXPECT_LT(at[b], next) << "bounce " << b;
  }
}

}  // namespace
}  // namespace bouncefit
