#include "msgs/msg_json.h"

#include <cmath>

namespace bouncefit {
namespace {

nlohmann::json Numbers(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v) a.push_back(FiniteOrNull(x));
  return a;
}

}  // namespace

nlohmann::json FiniteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

double SecondsSince(int64_t utime, int64_t t0_utime) {
  return static_cast<double>(utime - t0_utime) * 1e-6;
}

nlohmann::json ToJson(const ball_box_t& m, int64_t t0) {
  nlohmann::json j{{"t_s", SecondsSince(m.utime, t0)}, {"frame", m.frame}, {"found", static_cast<bool>(m.found)}};
  if (m.found) {
    j.update({{"cx_px", m.cx}, {"cy_px", m.cy}, {"x_px", m.x}, {"y_px", m.y}, {"w_px", m.w},
              {"h_px", m.h}, {"radius_px", m.radius_px}, {"pixel_count", m.pixel_count},
              {"aspect_ratio", m.aspect_ratio}, {"score", m.score}});
  }
  if (m.camera_dx != 0 || m.camera_dy != 0) j.update({{"camera_dx_px", m.camera_dx}, {"camera_dy_px", m.camera_dy}});
  return j;
}

nlohmann::json ToJson(const calibration_t& m, int64_t t0) {
  return {{"t_s", SecondsSince(m.utime, t0)},
          {"px_per_m", FiniteOrNull(m.px_per_m)},
          {"px_per_m_sigma", FiniteOrNull(m.px_per_m_sigma)},
          {"roll_rad", FiniteOrNull(m.roll_rad)},
          {"roll_sigma_rad", FiniteOrNull(m.roll_sigma_rad)},
          {"floor_px", FiniteOrNull(m.floor_px)},
          {"floor_sigma_px", FiniteOrNull(m.floor_sigma_px)},
          {"method", m.method},
          {"samples", m.samples}};
}

nlohmann::json ToJson(const bounce_peak_t& m, int64_t t0) {
  auto time_or_null = [t0](int64_t u) {
    return u ? nlohmann::json(SecondsSince(u, t0)) : nlohmann::json();
  };
  return {{"sequence", m.sequence},
          {"bounce", m.bounce},
          {"t_s", SecondsSince(m.apex_utime, t0)},
          {"height_m", FiniteOrNull(m.height_m)},
          {"height_px", FiniteOrNull(m.height_px)},
          {"height_sigma_m", FiniteOrNull(m.height_sigma_m)},
          {"flight_height_m", FiniteOrNull(m.flight_height_m)},
          {"impact_before_t_s", time_or_null(m.impact_before_utime)},
          {"impact_after_t_s", time_or_null(m.impact_after_utime)},
          {"emitted_t_s", m.emitted_utime ? nlohmann::json(SecondsSince(m.emitted_utime, t0)) : nlohmann::json()},
          {"sent_t_s", SecondsSince(m.utime, t0)},
          {"revision", m.revision},
          {"live_bounce", m.live_bounce},
          {"refit_height_m", FiniteOrNull(m.refit_height_m)},
          {"fused_height_m", FiniteOrNull(m.fused_height_m)},
          {"heard", m.heard}};
}

nlohmann::json ToJson(const fit_update_t& m, int64_t t0) {
  nlohmann::json coeffs = nlohmann::json::array();
  for (int i = 0; i < m.num_coeffs; ++i) {
    coeffs.push_back({{"name", m.names[i]},
                      {"value", FiniteOrNull(m.values[i])},
                      {"sigma", FiniteOrNull(m.sigmas[i])},
                      {"identifiable", static_cast<bool>(m.identifiable[i])}});
  }
  return {{"t_s", SecondsSince(m.utime, t0)},
          {"published_t_s", m.published_utime ? nlohmann::json(SecondsSince(m.published_utime, t0)) : nlohmann::json()},
          {"sequence", m.sequence},
          {"start_bounce", m.start_bounce},
          {"after_bounce", m.after_bounce},
          {"final", static_cast<bool>(m.final)},
          {"model", m.model},
          {"method", m.method},
          {"coefficients", coeffs},
          {"recorded_m", Numbers(m.recorded_m)},
          {"simulated_m", Numbers(m.simulated_m)},
          {"residual_m", FiniteOrNull(m.residual_m)},
          {"evaluations", m.evaluations},
          {"wall_time_s", m.wall_time_s},
          {"time_step_s", m.time_step_s},
          {"iterations", m.iterations}};
}

}  // namespace bouncefit
