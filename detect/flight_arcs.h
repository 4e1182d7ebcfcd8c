#pragma once
// The drop's arcs and what each foresees: under the calibration, the drag-aware flight model
// with the arc's fit; before it, a local curve of the first fall. An arc is refitted here (a
// young arc's first sample dropped when the others put it off the arc), and here is the gate
// a sample of it is followed with, the noise its own samples show and the impact that began
// the current arc.
#include <vector>

#include "detect/detector_scene.h"
#include "detect/flight_follower_config.h"

namespace bouncefit {

class FlightArcs {
 public:
  FlightArcs(const FlightFollowerConfig& config, const DetectorScene& scene);

  // Where the arc puts the ball at t: down (u) and along the floor (w), px, and its speed
  // down (px/s). False before a scale when the arc has too few samples for a curve.
  bool Predict(const DetectorArc& arc, double t, double* u, double* w, double* v_down) const;
  // Refits an arc under the calibration's globals, dropping a young arc's first sample
  // when the others put it off the arc.
  void Refit(DetectorArc& arc) const;
  // How far a sample at t may lie off the arc, whose model moves at v_down px/s there,
  // gap_frames after its last sample, px: the scene's gate for that speed, wider while the
  // arc is young or the noise not measured, and the scale's uncertainty carried to t.
  double FollowGate(const DetectorArc& arc, double t, double v_down, double gap_frames) const;
  // The arc's speed along the floor, px/s: its fit's, or before a scale from its last samples.
  double SidewaysSpeed(const DetectorArc& arc) const;
  // The noise an arc's own samples show about its fit, px per coordinate (0: too few).
  double Scatter(const DetectorArc& arc) const;

  // The arcs' samples as the calibrator takes them.
  std::vector<FlightArcData> Data() const;
  // Takes the arc fits of a calibration fitted to the arcs as they are.
  void TakeFits(const FlightFit& flight);
  // The impact that began the current arc, as the last calibration placed it (null: the
  // drop's first arc, or that impact not fitted).
  const FlightImpact* ImpactBeforeCurrent() const;
  // Times multiplied by k: the arcs' samples, apexes and speeds (their fits wait for a refit).
  void RescaleTime(double k);

  std::vector<DetectorArc>& arcs() { return arcs_; }
  const std::vector<DetectorArc>& arcs() const { return arcs_; }

 private:
  // How far the arc's prediction at t may be off for the uncertainty of the scale it is
  // followed with (FlightFollowerConfig::scale_gate_sigmas), px.
  double ScaleGatePx(const DetectorArc& arc, double t) const;
  double Down(const DetectorSample& s) const { return scene_.Down(s); }
  double Floor(const DetectorSample& s) const { return scene_.Floor(s); }

  const FlightFollowerConfig& config_;
  const DetectorScene& scene_;
  std::vector<DetectorArc> arcs_;
};

}  // namespace bouncefit
