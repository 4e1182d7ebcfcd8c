// The restitution law's stage 1 where the heights cannot tell the air's drag: the first
// fall's duration measures it (DragFromFall), and the final fit keeps what it measured.
// Truth: the point-mass drop of a ball three times heavier than its preset says (a 4 cm
// rubber ball run as `--ball pingpong`), which falls faster than the preset's drag allows.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fit/fit_models.h"
#include "fit/fit_session.h"
#include "fit/restitution_fit.h"
#include "model/ball_preset.h"
#include "model/model_by_name.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"

namespace bouncefit {
namespace {

PointMassDropResult HeavyDrop(double drop_m) {
  PointMassDropConfig c;
  c.ball = ResolveBallPreset("pingpong", 0, 0);
  c.ball.mass_kg *= 3;
  c.drop_height_m = drop_m;
  c.end_time_s = 4;
  return SimulatePointMassDrop(c);
}

CoefficientSpec DragSpec(const BallModel& model) {
  for (const auto& s : model.Coefficients())
    if (s.name == "drag_coefficient") return s;
  throw std::logic_error("no drag_coefficient");
}

TEST(DragFromFall, FindsTheDragAtWhichThePresetFallsInTheRecordedTime) {
  const BallPreset preset = ResolveBallPreset("pingpong", 0, 0);
  const PointMassDropResult truth = HeavyDrop(2.5);
  PointMassModel pm(preset);
  FitProblem p;
  p.simulation.drop_height_m = 2.5;
  p.start_fall_s = truth.impact_times_s.at(0);
  p.start_fall_sigma_s = 0.002;
  const TimedDrag d = DragFromFall(p, pm, {}, DragSpec(pm));
  // The same fall with a third of the mass: a third of Cd A / m.
  EXPECT_NEAR(d.value, preset.drag_coefficient / 3, 0.01);
  EXPECT_GT(d.sigma, 0);
  EXPECT_LT(d.sigma, 0.1);

  // Faster than a fall in a vacuum: not a fall from rest at that time.
  p.start_fall_s = std::sqrt(2 * 2.5 / 9.81) - 0.03;
  EXPECT_TRUE(std::isnan(DragFromFall(p, pm, {}, DragSpec(pm)).value));
  // Not timed.
  p.start_fall_s = std::nan("");
  EXPECT_TRUE(std::isnan(DragFromFall(p, pm, {}, DragSpec(pm)).value));
}

// Two rebounds cannot tell three coefficients: with the apexes' and impacts' times the drag
// comes from the fall, and the simulated first rebound is where the recorded one is.
TEST(RestitutionFit, TheFirstFallTimesTheDragTwoHeightsCannotTell) {
  const BallPreset preset = ResolveBallPreset("pingpong", 0, 0);
  const PointMassDropResult truth = HeavyDrop(2.5);
  ASSERT_GE(truth.apex_heights_m.size(), 3u);
  auto model = MakeBallModel("bullet-softbody", preset);
  PointMassModel quick(preset);
  FitSessionConfig cfg;
  ConfigureSessionForModel(*model, preset, &cfg);
  cfg.ensemble_members = 1;
  auto fit = [&](bool timed) {
    FitSession session(*model, &quick, cfg);
    for (int b = 0; b <= 2; ++b) {
      PeakInput p{0, b, truth.apex_heights_m[b], 0.001, 0};
      if (timed) {
        p.apex_s = truth.apex_times_s[b];
        if (b > 0) p.impact_before_s = truth.impact_times_s[b - 1];
      }
      session.AddPeak(p);
    }
    return session.FinalUpdate();
  };
  auto drag_of = [](const FitUpdate& u) {
    for (const auto& c : u.coefficients)
      if (c.name == "drag") return c;
    throw std::logic_error("no drag in the fit");
  };

  const FitUpdate timed = fit(true);
  const CoefficientEstimate drag = drag_of(timed);
  EXPECT_TRUE(drag.identifiable);
  EXPECT_NEAR(drag.value, preset.drag_coefficient / 3, 0.03);
  EXPECT_NE(drag.note.find("timed by the first fall"), std::string::npos) << drag.note;
  EXPECT_LE(timed.residual_m, 0.002);

  // The simulated first rebound's apex time against the recorded one (since the release).
  SimulationOptions so;
  so.drop_height_m = 2.5;
  so.duration_s = 2;
  so.max_bounces = 1;
  const SimulationResult s = model->Simulate(timed.values, so);
  ASSERT_TRUE(s.ok) << s.failure;
  ASSERT_FALSE(s.apex_times_s.empty());
  EXPECT_NEAR(s.apex_times_s[0], truth.apex_times_s[1], 0.008) << "a 120 fps frame";

  const FitUpdate untimed = fit(false);
  EXPECT_FALSE(drag_of(untimed).identifiable);
  EXPECT_DOUBLE_EQ(drag_of(untimed).value, preset.drag_coefficient);
}

}  // namespace
}  // namespace bouncefit
