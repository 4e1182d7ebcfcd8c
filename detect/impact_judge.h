#pragma once
// Whether the samples rising below a falling arc confirm an impact: near the floor (high
// above it, the arc's young fit turned down too early and they are its own), one the camera
// could have missed, and whether the arc before it was a hop straddling the impact before.
// It decides; the flight follower begins the next arc or gives the samples back.
#include <vector>

#include "detect/detector_events.h"
#include "detect/detector_scene.h"
#include "detect/flight_arcs.h"
#include "detect/flight_follower_config.h"

namespace bouncefit {

// What the rising samples below the current arc make.
enum class RisingVerdict {
  kWaiting,         // too few yet (strays at their front dropped)
  kImpact,          // an impact: the next arc begins with them
  kImpactAfterHop,  // ... and the current arc was a hop: the impact before it is withdrawn
  kOnTheArc,        // high above the floor: they are the current arc's
};

class ImpactJudge {
 public:
  ImpactJudge(const FlightFollowerConfig& config, const DetectorScene& scene, const FlightArcs& arcs,
              const DropHost& host);

  // Judges `rising` (time order, below the current arc `cur`), dropping from its front the
  // samples that start no rebound: a stray detection the next one is not above, or the front
  // of a pair whose impact the camera could not have missed.
  RisingVerdict Judge(const DetectorArc& cur, std::vector<DetectorSample>& rising) const;
  // The last sample of a falling arc of six or more, which an impact ends, may straddle it:
  // true when the samples before it put it off the arc (it would bend the fall, and the
  // scale with it).
  bool LastSampleStraddles(const DetectorArc& fall) const;

 private:
  bool NearTheFloor(const DetectorArc& cur, const std::vector<DetectorSample>& rising) const;
  // Whether the impact `rising` would confirm is one the camera could not have missed had it
  // happened: the contact, where the arc and that rebound meet (a trial fit, the state
  // unchanged), lies farther beyond every sample seen within a frame of it than the ball
  // travels from there at its modelled speed (at least half a frame's travel, for an exposure
  // straddling the contact; plus the gate), and the rebound does not rise by more than the
  // gate. A hand that moved the thing tracked up, down and stopped makes such a pair (a
  // falling arc extrapolated past where the thing stopped, a "rebound" of jitter); a ball
  // whose floor is out of view at the bottom of the picture rises again and is kept.
  bool ImpactNotSeen(const std::vector<DetectorSample>& rising) const;
  // At 24 fps with a long exposure, the frames either side of an impact can both show the
  // ball at the floor, a little apart: taken for an impact, a hop of two samples, and a
  // second impact. The hop is known for what it is when the rebound after it rises higher
  // than the hop could have (a bounced ball loses height at every impact): its samples are
  // dropped and its impact withdrawn, so that one impact, timed anew, joins the arcs either
  // side (its event goes out again with the same index).
  bool StraddlesItsImpact(const DetectorArc& cur, const std::vector<DetectorSample>& rising) const;
  double Down(const DetectorSample& s) const { return scene_.Down(s); }

  const FlightFollowerConfig& config_;
  const DetectorScene& scene_;
  const FlightArcs& arcs_;
  const DropHost& host_;
};

}  // namespace bouncefit
