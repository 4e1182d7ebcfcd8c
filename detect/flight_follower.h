#pragma once
// Following a drop in flight, arc by arc. Each sample is judged against the current arc's
// prediction (the drag-aware flight model under the calibration, or before it a local curve
// of the first fall): on it, it joins the arc and the arc is refitted; a sample that leaves
// the falling arc upwards, confirmed by the next ones, is an impact and begins the next arc;
// a lone sample off the arc is noise and is dropped; six in a row off it end the arc (at
// rest, caught, rolling). It owns the drop's arcs, the samples pending judgement and the
// drop's samples in flight (which a recalibration lets the closed arcs take back). What
// crosses into the rest of the drop (the scale refitted, an apex due, the drop ended) goes
// through the DropHost. It coordinates its parts, each with its own state or judgement:
// - FlightArcs (detect/flight_arcs.h): the drop's arcs, each one's prediction, refit and
//   gate;
// - OffArcSamples (detect/off_arc_samples.h): the samples the current arc turned away and
//   its misses in a row;
// - ImpactJudge (detect/impact_judge.h): whether rising samples below the arc confirm an
//   impact;
// - ArcContinuation (detect/arc_continuation.h): whether the samples an arc turned away are
//   still its flight;
// - FlightSamples (detect/flight_samples.h): the drop's samples in flight, which the closed
//   arcs take back under a new calibration.
#include <vector>

#include "detect/arc_continuation.h"
#include "detect/detector_events.h"
#include "detect/detector_scene.h"
#include "detect/flight_arcs.h"
#include "detect/flight_follower_config.h"
#include "detect/flight_samples.h"
#include "detect/impact_judge.h"
#include "detect/off_arc_samples.h"

namespace bouncefit {

class FlightFollower {
 public:
  FlightFollower(const FlightFollowerConfig& config, DetectorScene& scene, DropHost& host);
  // Its parts keep references to each other and to the config.
  FlightFollower(const FlightFollower&) = delete;
  FlightFollower& operator=(const FlightFollower&) = delete;

  // A drop starts with its first arc (refitted by the caller once a scale is known).
  void Start(DetectorArc first);
  // A sample of the drop in flight, kept whatever becomes of it (ReadmitSamples).
  void Saw(const DetectorSample& s) { seen_.Saw(s); }
  // Judges a sample of the drop in flight.
  void OnFlight(const DetectorSample& s, std::vector<DetectorEvent>& ev);
  // The drop ended: no arcs, nothing pending.
  void Reset();
  void RescaleTime(double k);

  // Refits an arc under the calibration's globals, dropping a young arc's first sample
  // when the others put it off the arc.
  void RefitArc(DetectorArc& arc) const { arcs_.Refit(arc); }
  // The arcs' samples as the calibrator takes them.
  std::vector<FlightArcData> ArcData() const { return arcs_.Data(); }
  // Takes the arc fits of a calibration fitted to the arcs as they are.
  void TakeFits(const FlightFit& flight) { arcs_.TakeFits(flight); }
  // Each arc closed by a fitted impact takes back the samples seen between its impacts that
  // lie on it under the current calibration (FlightSamples). True when an arc gained one.
  bool ReadmitSamples() { return seen_.ReadmitInto(arcs_); }
  // The noise an arc's own samples show about its fit, px per coordinate (0: too few).
  double ArcScatter(const DetectorArc& arc) const { return arcs_.Scatter(arc); }
  // The impact that began the current arc, as the last calibration placed it (null: the
  // drop's first arc, or that impact not fitted).
  const FlightImpact* ImpactBeforeCurrentArc() const { return arcs_.ImpactBeforeCurrent(); }

  std::vector<DetectorArc>& arcs() { return arcs_.arcs(); }
  const std::vector<DetectorArc>& arcs() const { return arcs_.arcs(); }
  const FlightFollowerConfig& config() const { return config_; }

 private:
  // A sample off the current arc (u: its place down; ru, rw: how far off, down and along the
  // floor, beyond `gate`; v_down: the arc's speed there): rising below the falling arc (an
  // impact's?) or off it otherwise; six in a row end the arc unless they are still its flight.
  void OnOffArc(const DetectorSample& s, double ru, double rw, double v_down, double gate, double u,
                std::vector<DetectorEvent>& ev);
  // The samples the young current arc turned away are that rebound (ArcContinuation).
  bool AdoptOffArcSamples(DetectorArc& cur);
  // The rising samples pending confirm an impact: the next arc begins with them (after the
  // current arc, when it was a hop straddling the impact before it, is forgotten).
  void ConfirmImpact(const DetectorSample& s, bool after_hop, std::vector<DetectorEvent>& ev);
  // Six samples in a row off the current arc: it takes them back when they are still its
  // flight, or the drop ends.
  void OnArcMissed(const DetectorSample& s, double u, std::vector<DetectorEvent>& ev);
  // The samples turned away join the arc, which is refitted.
  void TakeBack(DetectorArc& cur, const std::vector<DetectorSample>& samples);
  double Down(const DetectorSample& s) const { return scene_.Down(s); }
  double Floor(const DetectorSample& s) const { return scene_.Floor(s); }

  FlightFollowerConfig config_;
  DetectorScene& scene_;
  DropHost& host_;
  FlightArcs arcs_;
  OffArcSamples off_;
  FlightSamples seen_;
  ImpactJudge impacts_;
  ArcContinuation continuation_;
  bool rejudging_ = false;  // OnFlight judging a sample again after a refit of the scale
};

}  // namespace bouncefit
