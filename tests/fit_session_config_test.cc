// The fit session's settings on the real models: unknown values refused, the coefficients
// searched (never the ball's size, mass or the simulation's step), their order, and when the
// final fit is the restitution law's.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "fit/fit_models.h"
#include "fit/fit_session_config.h"
#include "model/point_mass_model.h"

namespace bouncefit {
namespace {

std::vector<std::string> Names(const std::vector<CoefficientSpec>& specs) {
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);
  return names;
}

TEST(FitSessionConfig, UnknownSettingsAreRefusedWithWhatIsKnown) {
  const PointMassModel model(*FindBallPreset("tennis"));
  ValidateFitSessionConfig(FitSessionConfig{}, model);
  // Each setting set to a value it does not know, and what the refusal lists.
  const std::vector<std::pair<void (*)(FitSessionConfig*), std::string>> bad = {
      {[](FitSessionConfig* c) { c->live_method = "newton"; }, "unknown live method 'newton' (known: gauss-newton, search)"},
      {[](FitSessionConfig* c) { c->objective = "bounces"; }, "unknown objective 'bounces' (known: segments, drop)"},
      {[](FitSessionConfig* c) { c->impact = "spring"; }, "unknown impact 'spring' (known: boost, restitution)"},
      {[](FitSessionConfig* c) { c->method = "cma"; }, "unknown fit method 'cma' (known: nlopt, paper)"},
      {[](FitSessionConfig* c) { c->free = {"restitution", "stiffness"}; },
       "model 'point-mass' has no coefficient 'stiffness'"},
  };
  for (const auto& [set, message] : bad) {
    FitSessionConfig c;
    set(&c);
    try {
      ValidateFitSessionConfig(c, model);
      ADD_FAILURE() << "accepted: " << message;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(e.what(), message);
    }
  }
}

TEST(FitSessionConfig, TheSoftBallsSearchedCoefficientsLeaveItsSizeAndStepAlone) {
  FitSetup setup;
  setup.ball = ResolveBallPreset("tennis");
  const FitModels m = MakeFitModels(setup);
  const std::vector<std::string> free = Names(FreeCoefficients(*m.model, m.session));
  ASSERT_FALSE(free.empty());
  for (const auto& name : free)  // the mesh's radius_edge_ratio is searched: the ball's radius is not
    for (const std::string never : {"mass", "radius_m", "diameter", "time_step", "iterations", "gravity"})
      EXPECT_EQ(name.find(never), std::string::npos) << name << " (" << never << ")";
  for (const std::string law : {"rebound_restitution", "rebound_restitution_per_mps", "drag"})
    EXPECT_NE(std::find(free.begin(), free.end(), law), free.end()) << law;
  // Every searched one has bounds to search within.
  for (const auto& s : FreeCoefficients(*m.model, m.session)) EXPECT_GT(s.upper, s.lower) << s.name;
  // The live order puts the configured priority first, then every other free one.
  const std::vector<std::string> order = LiveOrder(FreeCoefficients(*m.model, m.session), m.session);
  ASSERT_EQ(order.size(), free.size());
  EXPECT_EQ(std::vector<std::string>(order.begin(), order.begin() + 3),
            (std::vector<std::string>{"rebound_restitution", "rebound_restitution_per_mps", "drag"}));
  EXPECT_TRUE(UsesRestitutionLaw(m.session, *m.model, m.quick.get()));
  EXPECT_FALSE(UsesRestitutionLaw(m.session, *m.model, nullptr));  // nothing to start the law from
  FitSessionConfig boost = m.session;
  boost.impact = "boost";
  EXPECT_FALSE(UsesRestitutionLaw(boost, *m.model, m.quick.get()));
}

TEST(FitSessionConfig, NamedFreeCoefficientsAndTheFirstOnesInAnOrder) {
  const PointMassModel model(*FindBallPreset("pingpong"));
  FitSessionConfig c;
  EXPECT_EQ(Names(FreeCoefficients(model, c)).size(), 3u);  // e0, its slope, drag: all bounded
  c.free = {"drag_coefficient", "restitution"};
  const auto free = FreeCoefficients(model, c);
  ASSERT_EQ(free.size(), 2u);
  EXPECT_EQ(Names(FirstCoefficients(free, {"drag_coefficient", "restitution"}, 1)),
            std::vector<std::string>{"drag_coefficient"});
  EXPECT_EQ(Names(FirstCoefficients(free, {"restitution_per_mps", "restitution"}, 2)),
            std::vector<std::string>{"restitution"});  // not free: skipped
  c.live_priority = {"drag_coefficient"};
  EXPECT_EQ(LiveOrder(free, c).front(), "drag_coefficient");
}

}  // namespace
}  // namespace bouncefit
