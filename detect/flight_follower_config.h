#pragma once
// How a flight is followed (detect/flight_follower.h): the gates a sample of an arc is judged with, the samples a young
// arc may drop, what makes an impact (fields of BounceDetectorConfig).

namespace bouncefit {

struct FlightFollowerConfig {
  // A sample is followed with the noise gate and further by this many sigmas of the scale's
  // uncertainty, carried to the sample: a first fall of a few smeared frames gives gravity
  // to 7% (a phone's rolling shutter adds more), and an arc followed with it leaves its
  // samples with the square of the time.
  double scale_gate_sigmas = 3;
  // ... with the scale's relative uncertainty taken as at least this: a fall fits its own
  // gravity closely even when that is off (a release with a push of the hand reads gravity
  // 20-25% high, as a smeared fall can), and the first rebound must outlive it.
  double first_scale_min_rel_sigma = 0.08;
  // Times a recalibration lets the closed arcs take back their samples and fits again
  // (0: an arc keeps what it was followed with).
  int readmit_rounds = 2;
  // A young arc's first sample, off the arc its later samples make, is dropped: by the gate
  // when taken within straddle_frames frame periods of the impact that began the arc (it may
  // straddle it: an exposure of up to a frame, the impact's time as two young arcs place it);
  // later, only when off by off_arc_radius_share of the ball's radius (a smeared streak, a box
  // merged with a shadow), at most max_late_drops times per arc.
  double straddle_frames = 2.5;
  double off_arc_radius_share = 0.25;
  int max_late_drops = 2;
  int impact_confirm_samples = 2;  // samples off the falling arc, upwards, that make an impact
};

}  // namespace bouncefit
