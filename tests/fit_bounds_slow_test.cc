// The final fit (the restitution law on the Bullet soft ball, real Bullet runs) on drops of a
// ball that is not what its preset says: what the bounces put at a bound stays there, and
// the fit keeps within max(2 mm, 1% of the drop height).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fit/fit_models.h"
#include "fit/fit_session.h"
#include "model/ball_preset.h"
#include "model/model_by_name.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"

namespace bouncefit {
namespace {

// The preset's final fit on the apexes (down to 1 cm) of `real` dropped from drop_m.
FitUpdate FitAs(const BallPreset& preset, const BallPreset& real, double drop_m, bool drag) {
  PointMassDropConfig c;
  c.ball = real;
  c.drop_height_m = drop_m;
  c.drag = drag;
  c.end_time_s = 20;
  const PointMassDropResult truth = SimulatePointMassDrop(c);
  auto model = MakeBallModel("bullet-softbody", preset);
  PointMassModel quick(preset);
  FitSessionConfig cfg;
  ConfigureSessionForModel(*model, preset, &cfg);
  FitSession session(*model, &quick, cfg);
  session.AddPeak({0, 0, drop_m, 0.001, 0});
  for (size_t i = 1; i < truth.apex_heights_m.size() && i <= 8; ++i)
    if (truth.apex_heights_m[i] >= 0.01) session.AddPeak({0, static_cast<int>(i), truth.apex_heights_m[i], 0.001, 0});
  return session.FinalUpdate();
}

const CoefficientEstimate* Coefficient(const FitUpdate& u, const std::string& name) {
  for (const auto& c : u.coefficients)
    if (c.name == name) return &c;
  return nullptr;
}

// A ping-pong ball in a vacuum: the bounces put drag at 0, and there it stays (the preset's
// 0.47 held instead left 32 mm RMS over 6 bounces from 1 m).
TEST(FitBounds, NoDragStaysAtItsBound) {
  const BallPreset ball = ResolveBallPreset("pingpong", 0, 0);
  const FitUpdate u = FitAs(ball, ball, 1.0, false);
  std::printf("pingpong without drag: RMS %.2f mm over %zu bounces\n", 1000 * u.residual_m, u.recorded_m.size());
  EXPECT_TRUE(u.no_answer.empty()) << u.no_answer;
  EXPECT_LE(u.residual_m, std::max(0.002, 0.01 * 1.0));
  const CoefficientEstimate* drag = Coefficient(u, "drag");
  ASSERT_NE(drag, nullptr);
  EXPECT_EQ(drag->bound, "lower");
  EXPECT_DOUBLE_EQ(drag->value, 0);
  EXPECT_TRUE(drag->sigma > 0) << "one-sided, into the range";
  ASSERT_FALSE(u.held.empty());
  EXPECT_NE(u.held.front().find("bound"), std::string::npos) << u.held.front();
}

// An air-filled ball of 190 mm and 300 g run as the airball preset (150 mm, 60 g): its drag
// per mass is a third of the preset's; the fit takes what the bounces say.
TEST(FitBounds, ABallHeavierThanItsPresetIsFittedFromEveryHeight) {
  const BallPreset preset = ResolveBallPreset("airball", 0, 0);
  const BallPreset real = ResolveBallPreset("airball", 0.19, 0.3);
  for (double drop : {1.0, 1.5}) {
    const FitUpdate u = FitAs(preset, real, drop, true);
    std::printf("airball of 190 mm, 300 g from %.1f m: RMS %.2f mm over %zu bounces\n", drop, 1000 * u.residual_m,
                u.recorded_m.size());
    EXPECT_TRUE(u.no_answer.empty()) << u.no_answer;
    EXPECT_LE(u.residual_m, std::max(0.002, 0.01 * drop)) << drop;
  }
}

}  // namespace
}  // namespace bouncefit
