#pragma once
// Following a drop in flight, arc by arc. Each sample is judged against the current arc's
// prediction (the drag-aware flight model under the calibration, or before it a local curve
// of the first fall): on it, it joins the arc and the arc is refitted; a sample that leaves
// the falling arc upwards, confirmed by the next ones, is an impact and begins the next arc;
// a lone sample off the arc is noise and is dropped; six in a row off it end the arc (at
// rest, caught, rolling). It owns the drop's arcs, the samples pending judgement and the
// drop's samples in flight (which a recalibration lets the closed arcs take back). What
// crosses into the rest of the drop (the scale refitted, an apex due, the drop ended) goes
// through the DropHost.
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "detect/detector_events.h"
#include "detect/detector_scene.h"

namespace bouncefit {

// Following a flight (fields of BounceDetectorConfig).
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

class FlightFollower {
 public:
  FlightFollower(const FlightFollowerConfig& config, DetectorScene& scene, DropHost& host);

  // A drop starts with its first arc (refitted by the caller once a scale is known).
  void Start(DetectorArc first);
  // A sample of the drop in flight, kept whatever becomes of it (ReadmitSamples).
  void Saw(const DetectorSample& s);
  // Judges a sample of the drop in flight.
  void OnFlight(const DetectorSample& s, std::vector<DetectorEvent>& ev);
  // The drop ended: no arcs, nothing pending.
  void Reset();
  void RescaleTime(double k);

  // Refits an arc under the calibration's globals, dropping a young arc's first sample
  // when the others put it off the arc.
  void RefitArc(DetectorArc& arc);
  // The arcs' samples as the calibrator takes them.
  std::vector<FlightArcData> ArcData() const;
  // Takes the arc fits of a calibration fitted to the arcs as they are.
  void TakeFits(const FlightFit& flight);
  // Each arc closed by a fitted impact takes back the samples seen between its impacts that
  // lie on it under the current calibration, within the gate a sample is followed with. An
  // arc is followed with the scale of the moment: a first fall's few smeared frames at 24 fps
  // measured it 25% high, and the ends of every rebound after it, off that scale, were turned
  // away or dropped; the arcs then kept their five tops, which hold their curvature least.
  // True when an arc gained a sample.
  bool ReadmitSamples();
  // The noise an arc's own samples show about its fit, px per coordinate (0: too few).
  double ArcScatter(const DetectorArc& arc) const;
  // The impact that began the current arc, as the last calibration placed it (null: the
  // drop's first arc, or that impact not fitted).
  const FlightImpact* ImpactBeforeCurrentArc() const;

  std::vector<DetectorArc>& arcs() { return arcs_; }
  const std::vector<DetectorArc>& arcs() const { return arcs_; }
  const FlightFollowerConfig& config() const { return config_; }

 private:
  bool Predict(const DetectorArc& arc, double t, double* u, double* w, double* v_down) const;
  // The arc's speed along the floor, px/s: its fit's, or before a scale from its last samples.
  double SidewaysSpeed(const DetectorArc& arc) const;
  // How far the arc's prediction at t may be off for the uncertainty of the scale it is
  // followed with (FlightFollowerConfig::scale_gate_sigmas), px.
  double ScaleGatePx(const DetectorArc& arc, double t) const;
  bool AdoptOffArcSamples(DetectorArc& cur);
  // The release arc, young and not yet calibrated, turned away `missed` (time order) for
  // its misses: they continue its fall (below its last sample, faster and faster, free flight
  // for the ball's size), so the model lost the fall, not the ball. *fall_parabola: that
  // fall's DownParabola (dt from the last missed sample).
  bool YoungFallContinues(const DetectorArc& cur, const std::vector<DetectorSample>& missed,
                          Eigen::Vector3d* fall_parabola) const;
  // A rebound's samples and those it turned away for its misses (time order, all after it) are
  // one free flight, bent within a quarter of the drop's gravity: the gravity, not the ball,
  // left the arc.
  bool ArcContinues(const DetectorArc& cur, const std::vector<DetectorSample>& missed) const;
  // The rising samples pending confirm an impact: the next arc begins with them.
  void ConfirmImpact(const DetectorSample& s, std::vector<DetectorEvent>& ev);
  // At 24 fps with a long exposure, the frames either side of an impact can both show the
  // ball at the floor, a little apart: taken for an impact, a hop of two samples, and a
  // second impact. The hop is known for what it is when the rebound after it rises higher
  // than the hop could have (a bounced ball loses height at every impact): its samples are
  // dropped and its impact withdrawn, so that one impact, timed anew, joins the arcs either
  // side (its event goes out again with the same index).
  bool StraddlesItsImpact(const DetectorArc& cur) const;
  void ForgetStraddlingArc();
  bool NearTheFloor(const DetectorArc& cur) const;
  // Whether the impact the rising samples pending_up_ would confirm is one the camera could
  // not have missed had it happened: the contact, where the arc and that rebound meet (a trial
  // fit, the state unchanged), lies farther beyond every sample seen within a frame of it than
  // the ball travels from there at its modelled speed (at least half a frame's travel, for an
  // exposure straddling the contact; plus the gate), and the rebound does not rise by more
  // than the gate. A hand that moved the thing tracked up, down and stopped makes such a pair
  // (a falling arc extrapolated past where the thing stopped, a "rebound" of jitter); a ball
  // whose floor is out of view at the bottom of the picture rises again and is kept.
  bool ImpactNotSeen() const;
  double Down(const DetectorSample& s) const { return scene_.Down(s); }
  double Floor(const DetectorSample& s) const { return scene_.Floor(s); }

  FlightFollowerConfig config_;
  DetectorScene& scene_;
  DropHost& host_;
  std::vector<DetectorArc> arcs_;
  std::vector<DetectorSample> pending_up_, pending_off_;
  std::optional<DetectorSample> last_far_;  // the previous sample, when it lay beyond the ball's reach
  int misses_ = 0;  // consecutive samples off the current arc
  bool rejudging_ = false;  // OnFlight judging a sample again after a refit of the scale
  static constexpr size_t kFlightSeenKept = 4096;
  std::vector<DetectorSample> flight_seen_;  // this drop's samples in flight, kept or not
};

}  // namespace bouncefit
