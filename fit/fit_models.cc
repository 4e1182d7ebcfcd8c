#include "fit/fit_models.h"

#include <algorithm>
#include <cmath>

#include "fit/restitution_fit.h"
#include "model/coefficient_table.h"
#include "model/model_by_name.h"
#include "model/point_mass_model.h"
#include "model/soft_ball_model.h"

namespace bouncefit {

void ConfigureSessionForModel(const BallModel& model, const BallPreset& ball,
                              FitSessionConfig* config) {
  // rho A / 2m: the ball's air per unit of drag coefficient, for the restitution points.
  config->air_per_m_per_cd = 1.2 * M_PI * ball.diameter_m * ball.diameter_m / 4 / (2 * ball.mass_kg);
  const auto* soft = dynamic_cast<const SoftBallModel*>(&model);
  if (!soft) return;
  config->time_step_s = soft->config().time_step_s;
  config->iterations = soft->config().position_iterations;
  // Soft-ball sets can diverge (through the floor, exploding): candidate answers are
  // checked from the safe drop heights inside the final fit's search.
  config->safe_search = true;
  config->safe_min_bounce_m = std::max(config->safe_min_bounce_m, ball.chatter_hop_m());
  if (config->impact == "restitution") {
    // The rebound law's curve and the air are what the heights and flights tell; the
    // boost is the other law. Start: the model's defaults (the stored tables' stiff
    // contacts were chosen to make Bullet itself rebound) with the ball's preset curve.
    config->never_fit.push_back("rebound_boost");
    if (config->live_priority.empty())
      config->live_priority = {"rebound_restitution", "rebound_restitution_per_mps", "drag"};
    CoefficientValues start;
    for (const auto& s : model.Coefficients()) start[s.name] = s.default_value;
    start = WithRestitutionLaw(start, ball.restitution, ball.restitution_per_mps,
                               ball.drag_coefficient);
    for (const auto& [name, v] : start)
      if (!config->start.count(name)) config->start[name] = v;
    return;
  }
  config->never_fit.push_back("rebound_restitution");
  // Measured with bench/fit_bench.cc's screening: what moves the heights most, in order.
  if (config->live_priority.empty())
    config->live_priority = {"rebound_boost", "linear_stiffness", "contact_hardness", "drag",
                             "volume_conservation", "pressure"};
  // The boost's speed slope is fitted by the segment objective only (bounces from several
  // heights tell it apart); the free-running default keeps the search it was measured with.
  if (config->objective == "drop") config->never_fit.push_back("rebound_boost_per_mps");
  // Warm start: the model's coefficient table for this ball, when there is one (values the
  // model does not know are ignored by the session).
  if (const auto table = SoftBallPresetTable(ball.name))
    for (const auto& [name, v] : table->values)
      if (!config->start.count(name)) config->start[name] = v;
}

FitModels MakeFitModels(const FitSetup& setup) {
  FitModels m;
  m.ball = setup.ball;
  m.model = MakeBallModel(setup.model, m.ball);
  m.quick = std::make_unique<PointMassModel>(m.ball);
  m.session = setup.session;
  ConfigureSessionForModel(*m.model, m.ball, &m.session);
  return m;
}

}  // namespace bouncefit
