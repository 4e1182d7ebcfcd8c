#include "model/point_mass_drop.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace bouncefit {
namespace {

struct Dynamics {
  double g;
  double k;  // drag per unit mass: a = -g - k v|v|
  double Accel(double v) const { return -g - k * v * std::abs(v); }
};

PointMassState Rk4(const Dynamics& d, PointMassState s, double dt) {
  const double k1h = s.velocity_mps, k1v = d.Accel(s.velocity_mps);
  const double v2 = s.velocity_mps + 0.5 * dt * k1v;
  const double k2h = v2, k2v = d.Accel(v2);
  const double v3 = s.velocity_mps + 0.5 * dt * k2v;
  const double k3h = v3, k3v = d.Accel(v3);
  const double v4 = s.velocity_mps + dt * k3v;
  const double k4h = v4, k4v = d.Accel(v4);
  return {s.height_m + dt / 6 * (k1h + 2 * k2h + 2 * k3h + k4h),
          s.velocity_mps + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)};
}

// Smallest tau in (0, dt] (to ~1e-14 s) at which f(Rk4(s, tau)) changes sign; f(s) >= 0
// and f(Rk4(s, dt)) < 0 on entry.
template <typename F>
double BisectStep(const Dynamics& d, PointMassState s, double dt, F f) {
  double lo = 0, hi = dt;
  for (int i = 0; i < 200 && hi - lo > 1e-14; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (f(Rk4(d, s, mid)) < 0)
      hi = mid;
    else
      lo = mid;
  }
  return 0.5 * (lo + hi);
}

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("point-mass drop: " + what);
}

}  // namespace

PointMassState PointMassDropResult::At(double t_s) const {
  if (knots.empty() || t_s < knots.front().t) {
    if (knots.empty()) return {};
    return {knots.front().h, 0.0};  // held at the drop height
  }
  if (t_s >= knots.back().t) return {knots.back().h, knots.back().v};
  // First knot after t; the one before it is <= t, and the interval is non-empty (an
  // impact's two knots share a time: upper_bound lands past both, giving the rebound).
  auto it = std::upper_bound(knots.begin(), knots.end(), t_s,
                             [](double t, const Knot& k) { return t < k.t; });
  const Knot& k1 = *it;
  const Knot& k0 = *(it - 1);
  const double dt = k1.t - k0.t;
  const double s = (t_s - k0.t) / dt;
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
  const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  return {h00 * k0.h + h10 * dt * k0.v + h01 * k1.h + h11 * dt * k1.v,
          h00 * k0.v + h10 * dt * k0.a + h01 * k1.v + h11 * dt * k1.a};
}

PointMassDropResult SimulatePointMassDrop(const PointMassDropConfig& c) {
  Require(std::isfinite(c.drop_height_m) && c.drop_height_m >= 0,
          "drop height must be >= 0 m (got " + std::to_string(c.drop_height_m) + ")");
  Require(c.ball.diameter_m > 0, "ball diameter must be > 0 m");
  Require(c.ball.mass_kg > 0, "ball mass must be > 0 kg");
  Require(c.ball.drag_coefficient >= 0, "drag coefficient must be >= 0");
  Require(c.g_mps2 > 0, "g must be > 0 m/s^2");
  Require(c.air_density_kgpm3 >= 0, "air density must be >= 0 kg/m^3");
  Require(c.hold_s >= 0, "hold must be >= 0 s");
  Require(std::isfinite(c.launch_speed_mps) && std::abs(c.launch_speed_mps) <= 100,
          "launch speed must be within +-100 m/s");
  Require(c.dt_s > 0 && c.dt_s <= 0.01, "integration step must be in (0, 0.01] s");
  Require(c.end_time_s >= c.hold_s, "end time must not be before the release");
  Require(c.min_apex_height_m > 0, "minimum apex height must be > 0 m");

  const double area = std::numbers::pi * c.ball.radius_m() * c.ball.radius_m();
  const Dynamics d{c.g_mps2, c.drag ? 0.5 * c.air_density_kgpm3 * c.ball.drag_coefficient *
                                          area / c.ball.mass_kg
                                    : 0.0};

  PointMassDropResult r;
  r.release_time_s = c.hold_s;
  r.apex_times_s.push_back(c.hold_s);
  r.apex_heights_m.push_back(c.drop_height_m);
  double t = c.hold_s;
  PointMassState s{c.drop_height_m, c.launch_speed_mps};
  r.knots.reserve(static_cast<size_t>((c.end_time_s - c.hold_s) / c.dt_s) + 64);
  r.knots.push_back({t, s.height_m, s.velocity_mps, d.Accel(s.velocity_mps)});
  // Thrown up: the top of the throw, found below, replaces the release as apex 0.
  const bool thrown_up = c.launch_speed_mps > 0;
  if (thrown_up) {
    r.apex_times_s.clear();
    r.apex_heights_m.clear();
  }

  if (c.drop_height_m == 0 && c.launch_speed_mps <= 0) {  // already on the floor: nothing happens
    r.knots.back().a = 0;
    r.comes_to_rest = true;
    r.rest_time_s = t;
    r.end_time_s = c.end_time_s;
    return r;
  }

  while (t < c.end_time_s) {
    const double step = std::min(c.dt_s, c.end_time_s - t);
    PointMassState next = Rk4(d, s, step);
    if (next.height_m < 0) {
      const double tau =
          BisectStep(d, s, step, [](const PointMassState& x) { return x.height_m; });
      const PointMassState at = Rk4(d, s, tau);
      t += tau;
      const double v_in = std::min(at.velocity_mps, 0.0);
      r.knots.push_back({t, 0.0, v_in, d.Accel(v_in)});
      const double e = c.ball.RestitutionAt(-v_in);
      const double v_out = -e * v_in;
      r.impact_times_s.push_back(t);
      r.impact_speeds_mps.push_back(-v_in);
      r.restitutions.push_back(e);
      if (v_out * v_out / (2 * c.g_mps2) < c.min_apex_height_m) {
        r.knots.push_back({t, 0.0, 0.0, 0.0});
        r.comes_to_rest = true;
        r.rest_time_s = t;
        break;
      }
      s = {0.0, v_out};
      r.knots.push_back({t, 0.0, v_out, d.Accel(v_out)});
      continue;
    }
    if (s.velocity_mps > 0 && next.velocity_mps <= 0) {
      const double tau =
          BisectStep(d, s, step, [](const PointMassState& x) { return x.velocity_mps; });
      r.apex_times_s.push_back(t + tau);
      r.apex_heights_m.push_back(Rk4(d, s, tau).height_m);
    }
    t += step;
    s = next;
    r.knots.push_back({t, s.height_m, s.velocity_mps, d.Accel(s.velocity_mps)});
  }
  r.end_time_s = c.end_time_s;
  return r;
}

}  // namespace bouncefit
