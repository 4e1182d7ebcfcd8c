#pragma once
// Streaming bounce detection: push the tracker's observations one frame at a time, get
// events back as soon as they are certain (time is an input, nothing here reads a clock or
// prints).
//
// It composes four parts, each with its own state and its part of the configuration:
// DetectorScene (detect/detector_scene.h: the clock, the noise, the ball's size, the
// calibration), DropStart (detect/drop_start.h: how a drop starts), FlightFollower
// (detect/flight_follower.h: arcs, gating, impacts) and ApexLedger (detect/apex_ledger.h:
// apexes, their revision, the drop's summary). It dispatches each frame by phase (waiting,
// flight, rest), refits the calibration with the drop's arcs (deciding the clock, letting
// the arcs take back their samples) and ends drops.
//
// What it does, per drop ("sequence"):
//  - waits while the ball is held still; a release is a move down from the hold;
//  - follows each free-flight arc with the drag-aware flight model (detect/flight_model.h);
//    a sample that leaves the falling arc upwards, confirmed by the next one, is an impact;
//    a lone sample off the arc is noise and is dropped;
//  - calibrates (detect/calibrator.h) at the first impact from the release fall, and refits
//    G, drag and roll on every later arc;
//  - emits each apex the first frame that is `emit_after_apex_frames` past the fitted apex
//    time (fitted through the arc, not the top sample), in metres, with its uncertainty;
//  - ends the drop when a rebound is below what the camera resolves, when the arc breaks
//    (caught, rolling) or when the ball is lost; a later hold and release is a new sequence.
//
// Bounce 0 (the release height) needs the floor, which is unknown before the ball has hit
// it: in the first drop of a stream it is emitted when the first impact is confirmed (its
// latency from the release is the fall time plus a few frames, reported as such); in later
// drops the floor and scale are known and it is emitted as soon as the release is.
// A drop need not start with a release: a ball thrown, entering the view mid-flight or
// already bouncing when the clip began starts a sequence at its first ballistic arc (a few
// samples on one parabola, accelerating down). That arc's apex, when seen, is bounce 0 if
// the ball was seen before it (thrown from the hand) and bounce 1 otherwise (it came from
// an impact out of sight); the arcs after it count on from there.
// When the tracker found the ball only once it was falling (no hold seen), the release arc
// is a fall from rest whose vertex is fitted, and the fall alone does not tell G from drag:
// bounce 0 then waits for the scale the first rebound's rise pins, and goes out just before
// the first rebound's apex (or at the end of the drop if that rebound is too low).
#include <cstdint>
#include <string>
#include <vector>

#include "detect/apex_ledger.h"
#include "detect/calibrator.h"
#include "detect/detector_events.h"
#include "detect/detector_scene.h"
#include "detect/drop_start.h"
#include "detect/flight_follower.h"
#include "track/ball_observation.h"

namespace bouncefit {

// Each part's fields come from its own config (SceneConfig, DropStartConfig,
// FlightFollowerConfig, ApexConfig); the calibrator's and the loss of the ball are the
// detector's own.
struct BounceDetectorConfig : SceneConfig, DropStartConfig, FlightFollowerConfig, ApexConfig {
  CalibratorConfig calibration;
  double lost_s = 1.0;          // the ball unseen this long ends the drop

  bool IsValid(std::string* error) const;
};

class BounceDetector : private DropHost {
 public:
  // Throws std::invalid_argument with a one-line message for an invalid config.
  explicit BounceDetector(BounceDetectorConfig config);
  // The parts refer to each other: not copied, not moved.
  BounceDetector(const BounceDetector&) = delete;
  BounceDetector& operator=(const BounceDetector&) = delete;

  // One frame, in capture order (utime must not go backwards: std::invalid_argument).
  std::vector<DetectorEvent> Push(const BallObservation& observation);
  // End of stream: closes the drop in progress (its summary is then in Summaries()).
  std::vector<DetectorEvent> Finish();

  const Calibration& calibration() const { return scene_.calibration().calibration; }
  bool calibrated() const { return scene_.calibrated(); }
  const std::vector<SequenceSummary>& Summaries() const { return ledger_.summaries(); }
  double noise_px() const { return scene_.sigma(); }
  double time_scale() const { return scene_.scale(); }
  double frame_period_s() const { return scene_.frame_dt(); }

 private:
  enum class Phase { kWaiting, kFlight, kRest };

  void StartSequence(DropStartFound start, const DetectorSample& s,
                     std::vector<DetectorEvent>& ev);
  void OnRest(const DetectorSample& s, std::vector<DetectorEvent>& ev);
  // Takes a calibration fitted to the arcs as they are: the arcs' fits, the noise level.
  void ApplyCalibration(CalibrationResult res);
  // Every time held anywhere multiplied by k (the clock found slowed).
  void RescaleTime(double k);

  // DropHost: what the parts hand back.
  void Recalibrate(int64_t utime, std::vector<DetectorEvent>& ev) override;
  void EndSequence(const std::string& reason, std::vector<DetectorEvent>& ev) override;
  void OnSampleKept(const DetectorSample& s, std::vector<DetectorEvent>& ev) override;
  void OnNoSample(double t, int64_t utime, std::vector<DetectorEvent>& ev) override;
  void OnImpactConfirmed(const DetectorSample& s, std::vector<DetectorEvent>& ev) override;
  void OnWaiting(const DetectorSample& s, std::vector<DetectorEvent>& ev) override;
  bool ApexDue(const DetectorArc& arc, double t) const override;
  bool InFlight() const override { return phase_ == Phase::kFlight; }
  int Sequence() const override { return ledger_.sequence(); }
  int FirstBounce() const override { return ledger_.first_bounce(); }
  bool PeakEmitted(int bounce) const override { return ledger_.PeakEmitted(bounce); }
  void ForgetImpact(int index) override { ledger_.ForgetImpact(index); }

  BounceDetectorConfig config_;
  DetectorScene scene_;
  DropStart start_;
  FlightFollower follower_;
  ApexLedger ledger_;
  Phase phase_ = Phase::kWaiting;
};

}  // namespace bouncefit
