#pragma once
// The soft ball's artificial rebound (docs/MODEL.md, "the artificial extra force"), kept apart
// from Bullet so that the simulation and the exported tick callback run the same rule.
//
// A contact episode starts at the first step any node touches the floor (impact speed: the
// centre's downward speed the step before) and ends at the first step no node touches it
// while the centre moves up; then every node gets an upward velocity change. Two laws:
//  - boost (the paper's): rebound_boost x impact speed added on top of Bullet's own rebound,
//    the boost falling by rebound_boost_per_mps per m/s above 4.43 m/s;
//  - restitution (rebound_restitution > 0): the centre leaves the floor at e(v) x v upward,
//    e(v) = rebound_restitution - rebound_restitution_per_mps x v, whatever Bullet's contact
//    gave: a first kick at touch (or at the deepest point) sends the centre up at e(v) v,
//    lift-off corrects what the contact added meanwhile (either sign). The law is the
//    continuous point mass's, not the time step's: the impact speed is what a point mass
//    has on the floor given the ball's state as it touches (up to a step above the floor,
//    at the step's speed), and each kick sets the speed from which Bullet's semi-implicit
//    Euler steps reach the point mass's apex from where the ball is then. Without this the
//    rebound rose from up to a step high as fast as from the floor (a softball's 8 cm bounce
//    7% high) and the integrator took v dt / 2 off every apex (2 mm at 2 m/s): errors that
//    change with speed, read by a fit as a restitution slope that is not the ball's.
//    Restitution against impact speed is what a recorded drop measures and what transfers to
//    another drop height.
// Episodes longer than max_contact_s are a ball at rest (no kick).
#include <vector>

namespace bouncefit {

struct ReboundLaw {
  double boost = 0;
  double boost_per_mps = 0;
  double restitution = 0;          // > 0: the restitution law replaces the boost
  double restitution_per_mps = 0;
  double max_contact_s = 0.1;
  double gravity_mps2 = 9.81;
  double time_step_s = 1.0 / 480;  // the simulation's fixed step
  // Restitution law: the first kick at the first contact step (true; the ball turns at once,
  // as the point mass does, so impacts keep time: docs/MODEL.md) or at the deepest point.
  bool at_touch = true;
  // ... and the world sets the ball down on the floor as it turns (every node moved down by
  // the bottom's height above the floor), and a step later back to where the point mass is
  // (ContactTracker::shift): the rebound then starts where and when the point mass's does (not
  // the time to fall and rise through that height again: 7 ms a bounce for a softball turned
  // 9 mm up; nor a step early).
  bool set_down = true;

  static constexpr double kReferenceSpeed = 4.43;  // m/s, sqrt(2 g 1 m): the boost's pivot
  bool Active() const { return boost > 0 || boost_per_mps != 0 || restitution > 0; }
  // Upward velocity change after an impact at impact_speed (m/s, >= 0: the centre's speed
  // the step before the touch), the centre leaving at leave_speed (m/s, up positive). The
  // restitution law also takes the bottom's height above the floor as the ball touched and
  // now (m; it rebounds as the point mass would from the floor).
  double Kick(double impact_speed, double leave_speed, double touch_gap_m = 0, double bottom_m = 0) const;
  // Restitution law: where the continuous point mass's bottom is a step after the ball
  // touched touch_gap_m above the floor (it still had the gap to fall, then rose for the rest
  // of the step), m above the floor.
  double HeightAfterStep(double impact_speed, double touch_gap_m) const;
};

struct ContactEpisode {
  double start_s = 0;         // first step with a node on the floor
  double end_s = 0;           // lift-off (0 while still in contact)
  double impact_speed_mps = 0;
  double start_y_m = 0, end_y_m = 0;  // centre heights then
  double floor_y_m = 0;               // the centre's height with the bottom on the floor, as it touched
  double end_vy_mps = 0;              // centre's upward speed leaving (the kick included)
  // Where the falling arc (before start_s) and the rising arc (after end_s), continued as
  // drag-free parabolas, meet: the impact time a video measures.
  double ArcsMeet(double g_mps2) const;
};

// Follows the contact episodes of one run, step by step.
class ContactTracker {
 public:
  explicit ContactTracker(ReboundLaw law) : law_(law) {}
  // Called every step before Bullet steps: time, whether any node touches the floor, the
  // centre's height and vertical velocity, the lowest node's height above the floor.
  // Returns the upward velocity to give every node now.
  double Step(double t_s, bool contact, double centre_y_m, double centre_vy_mps, double bottom_m = 0);
  const std::vector<ContactEpisode>& episodes() const { return episodes_; }
  bool in_contact() const { return in_contact_; }
  // How far to move the ball down this step, m, before its kick (set down on the floor as it
  // turns; a step later back to where the point mass is, which had the gap still to fall).
  double shift() const { return shift_; }
  // Every closed episode's ArcsMeet() whose impact was faster than min_speed_mps: the impact
  // times as the detector measures them on video.
  std::vector<double> ImpactTimes(double min_speed_mps = 0.05) const;

 private:
  ReboundLaw law_;
  bool in_contact_ = false;
  bool turned_ = false;  // the restitution law's first kick was given
  bool retarget_ = false;  // set down at touch: the next step puts it on the point mass's arc
  double pm_height_next_ = 0;  // the point mass's bottom height a step after the touch
  double shift_ = 0;
  double prev_vy_ = 0;
  std::vector<ContactEpisode> episodes_;
};

}  // namespace bouncefit
