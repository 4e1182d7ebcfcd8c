#include "pipeline/message_mapping.h"

namespace bouncefit {

fit_update_t ToFitUpdateMsg(const FitUpdate& u) {
  fit_update_t m{};
  m.utime = u.utime;
  m.sequence = u.sequence;
  m.after_bounce = u.after_bounce;
  m.final = u.final;
  m.model = u.model;
  m.method = u.method;
  m.num_coeffs = static_cast<int32_t>(u.coefficients.size());
  for (const auto& c : u.coefficients) {
    m.names.push_back(c.name);
    m.values.push_back(c.value);
    m.sigmas.push_back(c.sigma);
    m.identifiable.push_back(c.identifiable);
  }
  m.num_bounces = static_cast<int32_t>(u.recorded_m.size());
  m.recorded_m = u.recorded_m;
  m.simulated_m = u.simulated_m;
  m.simulated_m.resize(u.recorded_m.size(), 0.0);
  m.residual_m = u.residual_m;
  m.evaluations = u.evaluations;
  m.wall_time_s = u.wall_time_s;
  m.time_step_s = u.time_step_s;
  m.iterations = u.iterations;
  return m;
}

PeakInput ToPeakInput(const bounce_peak_t& m) {
  PeakInput p;
  p.sequence = m.sequence;
  p.bounce = m.bounce;
  p.height_m = m.height_m;
  p.sigma_m = m.height_sigma_m > 0 ? m.height_sigma_m : 0;
  p.utime = m.utime;
  if (m.impact_before_utime != 0) p.impact_before_s = 1e-6 * static_cast<double>(m.impact_before_utime);
  if (m.apex_utime != 0) p.apex_s = 1e-6 * static_cast<double>(m.apex_utime);
  return p;
}

}  // namespace bouncefit
