// The free-running drop as an ensemble, and the safety check over the heights a user may
// drop the ball from (fit/drop_ensemble.h), on real models.
#include <gtest/gtest.h>

#include "fit/drop_ensemble.h"
#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/point_mass_model.h"
#include "model/soft_ball_model.h"

namespace bouncefit {
namespace {

TEST(DropEnsemble, PointMassMembersAgreeWithTheSingleRun) {
  const PointMassModel model(*FindBallPreset("tennis"));
  SimulationOptions drop;
  drop.drop_height_m = 1.0;
  const DropEnsemble e = SimulateDropEnsemble(model, {}, drop);
  ASSERT_TRUE(e.ok) << e.failure;
  ASSERT_GE(e.mean_m.size(), 3u);
  ASSERT_EQ(e.runs.size(), 8u);
  // +-0.1 mm of release height moves a non-chaotic ball's bounces by far less than a mm.
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(e.mean_m[i], e.single_m[i], 1e-4) << i;
    EXPECT_LT(e.sd_m[i], 1e-4) << i;
  }
}

TEST(DropEnsemble, UnsafeDropFindsTheStoredAirballDivergingFromThirtyCentimetres) {
  const BallPreset airball = *FindBallPreset("airball");
  const SoftBallModel model(airball);
  const auto table = SoftBallPresetTable("airball");
  ASSERT_TRUE(table.has_value());
  const std::string unsafe = UnsafeDrop(model, table->values, {0.3, 2.0}, 2);
  EXPECT_NE(unsafe.find("diverges dropped from 0.3 m"), std::string::npos) << unsafe;
  // It goes through the floor near rest, after its bounces: two bounces do not show it.
  EXPECT_EQ(UnsafeDrop(model, table->values, {0.3}, 2, 2), "");
  // The ping-pong ball's stored set runs to rest from both.
  const SoftBallModel pingpong(*FindBallPreset("pingpong"));
  EXPECT_EQ(UnsafeDrop(pingpong, SoftBallPresetTable("pingpong")->values, {0.3, 2.0}, 2), "");
}

}  // namespace
}  // namespace bouncefit
