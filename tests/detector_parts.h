#pragma once
// Test helper: the bounce detector's parts (detect/detector_scene.h, drop_start.h,
// flight_follower.h, apex_ledger.h) wired together by the least a DropHost must do, so that
// each part's test can drive it with a rendered drop without the BounceDetector: the scale
// refitted with the drop's arcs (no clock decision, no samples taken back), the apexes
// handed to the ledger, the drop ended. It records what the parts asked of it. A part's test
// may stop it mid-drop (Feed) and ask the part's own class about the drop as it is then.
#include <limits>
#include <string>
#include <vector>

#include "detect/bounce_detector.h"
#include "detect_sim.h"
#include "track/ball_observation.h"

namespace bouncefit::testing {

class PartsHost : public DropHost {
 public:
  explicit PartsHost(const BounceDetectorConfig& c = {})
      : scene(c, c.calibration), start(c, scene), follower(c, scene, *this),
        ledger(c, scene, follower, *this) {}

  // Every observation, then the end of the stream; the events the parts sent.
  std::vector<DetectorEvent> Run(const std::vector<BallObservation>& obs) {
    std::vector<DetectorEvent> ev = Feed(obs);
    if (in_flight) EndSequence("end of stream", ev);
    return ev;
  }
  // The observations before stream time `until` (s), the drop left as it is then.
  std::vector<DetectorEvent> Feed(const std::vector<BallObservation>& obs,
                                  double until = std::numeric_limits<double>::infinity()) {
    std::vector<DetectorEvent> ev;
    for (const auto& o : obs) {
      if (o.utime * 1e-6 >= until) break;
      double t = 0;
      if (!scene.Advance(o.utime, &t) || !o.found) continue;
      DetectorSample s{t, o.cx, o.cy, o.radius_px, o.utime};
      samples.push_back(s);
      scene.Saw(s);
      scene.set_last_seen_t(t);
      if (in_flight) {
        follower.Saw(s);
        follower.OnFlight(s, ev);
      } else if (!ended_at_rest) {
        OnWaiting(s, ev);
      }
    }
    return ev;
  }

  void Recalibrate(int64_t utime, std::vector<DetectorEvent>& ev) override {
    CalibrationInput in;
    in.utime = utime;
    in.arcs = follower.ArcData();
    in.radius_px = scene.RadiusPx();
    FlightGlobals globals;
    if (scene.calibrated()) {
      globals = scene.calibration().flight.globals;
      in.previous_globals = &globals;
    }
    CalibrationResult res = scene.calibrator().Calibrate(in);
    if (!res.flight.ok) return;
    scene.Adopt(std::move(res), ledger.sequence());
    follower.TakeFits(scene.calibration().flight);
    ++recalibrations;
  }
  void EndSequence(const std::string& reason, std::vector<DetectorEvent>& ev) override {
    if (follower.arcs().size() >= 2) Recalibrate(scene.last_utime(), ev);
    ledger.CloseDrop(reason, ev);
    follower.Reset();
    ledger.ResetDrop();
    start.Reset();
    in_flight = false;
    ended_at_rest = reason == "rest";
    end_reasons.push_back(reason);
  }
  void OnSampleKept(const DetectorSample& s, std::vector<DetectorEvent>& ev) override {
    ledger.OnSampleKept(s, ev);
  }
  void OnNoSample(double t, int64_t utime, std::vector<DetectorEvent>& ev) override {
    ledger.TryEmitApex(t, utime, false, ev);
  }
  void OnImpactConfirmed(const DetectorSample& s, std::vector<DetectorEvent>& ev) override {
    impact_confirmed_t.push_back(s.t);
    Recalibrate(s.utime, ev);
    ledger.OnImpact(s.utime, ev);
  }
  void OnWaiting(const DetectorSample& s, std::vector<DetectorEvent>& ev) override {
    auto found = start.OnWaiting(s);
    if (!found) return;
    found->arc.release = !found->arc.entered;
    starts.push_back(*found);
    ledger.StartDrop(found->first_bounce);
    follower.Start(std::move(found->arc));
    in_flight = true;
  }
  bool ApexDue(const DetectorArc& arc, double t) const override { return ledger.ApexDue(arc, t); }
  bool InFlight() const override { return in_flight; }
  int Sequence() const override { return ledger.sequence(); }
  int FirstBounce() const override { return ledger.first_bounce(); }
  bool PeakEmitted(int bounce) const override { return ledger.PeakEmitted(bounce); }
  void ForgetImpact(int index) override { ledger.ForgetImpact(index); }

  DetectorScene scene;
  DropStart start;
  FlightFollower follower;
  ApexLedger ledger;
  bool in_flight = false, ended_at_rest = false;
  int recalibrations = 0;
  std::vector<DropStartFound> starts;
  std::vector<double> impact_confirmed_t;  // the sample that confirmed each impact, s
  std::vector<std::string> end_reasons;
  std::vector<DetectorSample> samples;  // every sample fed, in time order
};

// Where a clip's camera shows the ball's centre at t, px down the picture (no roll).
inline double TruthDown(const SimClip& clip, double t) {
  return clip.options.floor_y - clip.truth.At(t).height_m * clip.options.px_per_m - clip.radius_px;
}

// A rendered drop fed to the parts and stopped mid-flight (Stop), with the follower's arcs as
// they are then in a FlightArcs of its own, for a part's test to ask about them.
struct StoppedDrop {
  explicit StoppedDrop(const SimOptions& o = {}) : clip(MakeSimClip(o)), arcs(config, host.scene) {
    PartsHost all;
    all.Run(clip.obs);
    samples = all.samples;
  }
  // The parts fed every observation before stream time `until` (s).
  void Stop(double until) {
    host.Feed(clip.obs, until);
    arcs.arcs() = host.follower.arcs();
  }
  // The clip's first n samples after stream time t (s), as the parts see them.
  std::vector<DetectorSample> After(double t, size_t n) const {
    std::vector<DetectorSample> out;
    for (const auto& s : samples)
      if (s.t > t && out.size() < n) out.push_back(s);
    return out;
  }
  double frame() const { return 1 / clip.options.fps; }

  const FlightFollowerConfig config;
  SimClip clip;
  std::vector<DetectorSample> samples;  // the whole clip's
  PartsHost host;
  FlightArcs arcs;
};

}  // namespace bouncefit::testing
