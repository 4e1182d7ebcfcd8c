#include "pipeline/message_mapping.h"

#include <cmath>

namespace bouncefit {

calibration_t ToCalibrationMsg(const Calibration& c) {
  calibration_t m{};
  m.utime = c.utime;
  m.px_per_m = c.px_per_m;
  m.px_per_m_sigma = c.px_per_m_sigma;
  m.roll_rad = c.roll_rad;
  m.roll_sigma_rad = c.roll_sigma_rad;
  m.floor_px = c.floor_px;
  m.floor_sigma_px = c.floor_sigma_px;
  m.method = c.method;
  m.samples = c.samples;
  return m;
}

bounce_peak_t ToBouncePeakMsg(const BouncePeak& p) {
  bounce_peak_t m{};
  m.utime = p.utime;
  m.sequence = p.sequence;
  m.bounce = p.bounce;
  m.apex_utime = p.apex_utime;
  m.height_m = p.height_m;
  m.height_px = p.height_px;
  m.height_sigma_m = p.height_sigma_m;
  m.flight_height_m = p.flight_height_m;
  m.impact_before_utime = p.impact_before_utime;
  m.impact_after_utime = p.impact_after_utime;
  m.emitted_utime = p.emitted_utime;
  m.revision = 0;
  m.live_bounce = p.bounce;
  m.refit_height_m = m.fused_height_m = NAN;
  return m;
}

std::vector<bounce_peak_t> RefittedPeakMsgs(const SequenceSummary& d, int64_t now_utime) {
  std::vector<bounce_peak_t> out;
  for (const BouncePeak& p : d.peaks) {
    const double refit = d.FinalHeightOf(p.bounce);
    if (!std::isfinite(refit)) continue;
    bounce_peak_t m = ToBouncePeakMsg(p);
    m.height_px = m.height_m > 0 ? m.height_px * refit / m.height_m : NAN;
    m.height_m = refit;
    m.utime = m.emitted_utime = now_utime;
    m.revision = 2;
    m.refit_height_m = refit;
    out.push_back(m);
  }
  return out;
}

fit_update_t ToFitUpdateMsg(const FitUpdate& u) {
  fit_update_t m{};
  m.utime = u.utime;
  m.sequence = u.sequence;
  m.start_bounce = u.start_bounce;
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
