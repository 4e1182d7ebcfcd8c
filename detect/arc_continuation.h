#pragma once
// Whether the samples an arc turned away (time order, after its own) are still its flight,
// and not an impact or the end of the drop: a young rebound's, whose first smeared samples
// made it extrapolate wrongly; a young release fall's, whose model lost the fall; a long
// arc's, turned away by a gravity fitted mostly to another arc.
#include <Eigen/Core>

#include <vector>

#include "detect/detector_scene.h"
#include "detect/flight_arcs.h"

namespace bouncefit {

class ArcContinuation {
 public:
  ArcContinuation(const DetectorScene& scene, const FlightArcs& arcs);

  // A rebound's first samples at a low frame rate: the one straddling the impact is smeared,
  // and an arc of two or three samples extrapolates its error for every frame after (at
  // 24 fps the next sample is then tens of pixels off). When the samples it turned away, high
  // or low, agree with one arc together with its samples that fit too, they are that
  // rebound: *rebound, the arc refitted with them.
  bool YoungReboundContinues(const DetectorArc& cur, const std::vector<DetectorSample>& missed,
                             DetectorArc* rebound) const;
  // The release arc, young and not yet calibrated, turned away `missed` for its misses: they
  // continue its fall (below its last sample, faster and faster, free flight for the ball's
  // size), so the model lost the fall, not the ball. *fall_parabola: that fall's
  // DownParabola (dt from the last missed sample).
  bool YoungFallContinues(const DetectorArc& cur, const std::vector<DetectorSample>& missed,
                          Eigen::Vector3d* fall_parabola) const;
  // A rebound's samples and those it turned away for its misses are one free flight, bent
  // within a quarter of the drop's gravity: the gravity, not the ball, left the arc.
  bool ArcContinues(const DetectorArc& cur, const std::vector<DetectorSample>& missed) const;

 private:
  double Down(const DetectorSample& s) const { return scene_.Down(s); }

  const DetectorScene& scene_;
  const FlightArcs& arcs_;
};

}  // namespace bouncefit
