#include "model/rebound_kick.h"

#include <algorithm>
#include <cmath>

namespace bouncefit {

double ReboundLaw::Kick(double impact_speed, double leave_speed, double touch_gap_m,
                        double bottom_m) const {
  if (restitution > 0) {
    // A re-contact while rising (a node swinging down) is no impact: nothing to set.
    if (impact_speed <= 0) return 0;
    const double g = gravity_mps2, dt = time_step_s;
    // The step's speed as it touches (one step of gravity after the step before), and the
    // point mass's on the floor: semi-implicit Euler falls g dt / 2 slow, and the touch is
    // up to a step above the floor.
    const double v_step = impact_speed + g * dt;
    const double v = std::sqrt(v_step * v_step + g * dt * v_step + 2 * g * std::max(0.0, touch_gap_m));
    const double e = std::clamp(restitution - restitution_per_mps * v, 0.0, 1.0);
    const double apex = (e * v) * (e * v) / (2 * g);  // the point mass's, bottom above the floor
    // From bottom_m at speed w the steps rise w^2 / 2g - w dt / 2: reach the apex.
    const double rise = std::max(0.0, apex - std::max(0.0, bottom_m));
    const double w = g * dt / 2 + std::sqrt(g * dt / 2 * (g * dt / 2) + 2 * g * rise);
    return w - leave_speed;
  }
  const double b = std::max(0.0, boost - boost_per_mps * (impact_speed - kReferenceSpeed));
  return b * impact_speed;
}

double ReboundLaw::HeightAfterStep(double impact_speed, double touch_gap_m) const {
  const double g = gravity_mps2, dt = time_step_s;
  const double v_step = impact_speed + g * dt;
  const double v_gap = std::sqrt(v_step * v_step + g * dt * v_step);  // continuous, at the gap
  const double gap = std::max(0.0, touch_gap_m);
  const double v = std::sqrt(v_gap * v_gap + 2 * g * gap);             // on the floor
  const double e = std::clamp(restitution - restitution_per_mps * v, 0.0, 1.0);
  // The point mass reaches the floor tau after now and rises for the rest of the step.
  const double s = std::max(0.0, dt - (v - v_gap) / g);
  return std::max(0.0, e * v * s - g * s * s / 2);
}

double ContactEpisode::ArcsMeet(double g) const {
  // y_s + v_s (t - t_s) - g/2 (t - t_s)^2 = y_e + v_e (t - t_e) - g/2 (t - t_e)^2 is linear in t.
  const double v_s = -impact_speed_mps, dt = end_s - start_s;
  const double b = v_s - end_vy_mps - g * dt;
  const double a = start_y_m - end_y_m - v_s * start_s + end_vy_mps * end_s + 0.5 * g * dt * (start_s + end_s);
  const double t = b < 0 ? -a / b : 0.5 * (start_s + end_s);
  return std::clamp(t, start_s - dt, end_s + dt);
}

double ContactTracker::Step(double t, bool contact, double y, double vy, double bottom) {
  double kick = 0;
  shift_ = 0;
  if (!in_contact_ && contact) {
    in_contact_ = true;
    turned_ = false;
    episodes_.push_back({t, 0, std::max(0.0, -prev_vy_), y});
    episodes_.back().floor_y_m = y - std::max(0.0, bottom);
    if (law_.restitution > 0 && law_.at_touch) {  // rebound at once, as a hard ball does
      turned_ = true;
      const ContactEpisode& e = episodes_.back();
      if (law_.set_down) {
        // A re-contact while rising (a node swinging down) is no impact: nothing to set.
        if (e.impact_speed_mps > 0) {
          shift_ = std::max(0.0, y - e.floor_y_m);  // onto the floor
          kick = law_.Kick(e.impact_speed_mps, vy, shift_, 0.0);
          pm_height_next_ = law_.HeightAfterStep(e.impact_speed_mps, shift_);
          retarget_ = true;
        }
      } else {
        kick = law_.Kick(e.impact_speed_mps, vy, y - e.floor_y_m, y - e.floor_y_m);
      }
    }
  } else if (in_contact_) {
    ContactEpisode& e = episodes_.back();
    const bool rest = !law_.Active() || t - e.start_s >= law_.max_contact_s;
    const bool retarget = retarget_ && !rest;
    retarget_ = false;
    if (!contact && vy > 0) {  // lift-off
      in_contact_ = false;
      e.end_s = t;
      if (retarget) shift_ = std::max(0.0, y - e.floor_y_m - pm_height_next_);
      if (!rest) kick = law_.Kick(e.impact_speed_mps, vy, e.start_y_m - e.floor_y_m, y - e.floor_y_m - shift_);
      e.end_y_m = y;
      e.end_vy_mps = vy + kick;
    } else if (retarget) {
      // The step after the set-down: back to where the point mass is (it still had the gap
      // to fall), on its arc.
      shift_ = std::max(0.0, y - e.floor_y_m - pm_height_next_);
      kick = law_.Kick(e.impact_speed_mps, vy, e.start_y_m - e.floor_y_m, y - e.floor_y_m - shift_);
    } else if (!rest && law_.restitution > 0 && !turned_ && vy >= 0) {
      // Not at touch: at the deepest point (a soft contact may never lift off by itself at
      // low speed, so the law does not wait for Bullet's own rebound).
      turned_ = true;
      kick = law_.Kick(e.impact_speed_mps, vy, e.start_y_m - e.floor_y_m, y - e.floor_y_m);
    }
  }
  prev_vy_ = vy;
  return kick;
}

std::vector<double> ContactTracker::ImpactTimes(double min_speed_mps) const {
  std::vector<double> out;
  for (const auto& e : episodes_)
    if (e.end_s > e.start_s && e.impact_speed_mps > min_speed_mps) out.push_back(e.ArcsMeet(law_.gravity_mps2));
  return out;
}

}  // namespace bouncefit
