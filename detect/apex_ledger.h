#pragma once
// The apexes of a drop and their revision. Each arc's apex goes out the first frame that is
// `emit_after_apex_frames` past its fitted apex time (fitted through the arc, not the top
// sample), in metres over the floor under that arc, with its uncertainty; the scale is
// refitted first with that arc. Peaks go out in bounce order: the release height (bounce 0)
// needs the floor, known at the first impact, and a fall whose hold was not seen waits for
// the first rebound, which pins gravity against drag. An arc whose apex went unreported is
// reported late, at the impact that ends it. When the drop ends, every apex is refitted with
// all its arcs (each over the floor where its own two contacts are) and the drop's summary
// holds the revised heights, the flight-time heights and the restitution trend. It numbers
// the drops of the stream and their bounces, and keeps the drop's peaks and impacts.
#include <cstdint>
#include <string>
#include <vector>

#include "detect/apex_flight_check.h"
#include "detect/detector_events.h"
#include "detect/detector_scene.h"
#include "detect/flight_follower.h"

namespace bouncefit {

// The apexes (fields of BounceDetectorConfig).
struct ApexConfig {
  double emit_after_apex_frames = 1.0;  // emit this many frame periods after the fitted apex
  int bounce0_rising_samples = 8;  // rising samples after the first impact before bounce 0
                                   // (release seen held; otherwise at the first rebound's apex)
  // Apex height of bounces >= 1: true = FitArcApex (model/arc_apex.h, the parabola shared
  // with the models) through the arc's samples within arc_apex_window_s of the fitted
  // vertex, drag's departure from a parabola removed; false (or too few samples there) =
  // the vertex of the drag-aware arc fitted through all the arc's samples. Both measure
  // within 0.1 mm RMS of each other on the synth presets (docs/ACCURACY.md).
  bool use_arc_apex = true;
  double arc_apex_window_s = 0.15;
  // A rebound's apex is checked against the flight times around it before it goes out
  // (detect/apex_flight_check.h): each impact's time is taken as known to this many frame
  // periods, and a disagreement beyond flight_check_sigmas combined sigmas holds, replaces or
  // withholds the apex (0 sigmas: no check).
  double impact_time_sigma_frames = 0.3;
  double flight_check_sigmas = 3;
  // A rebound higher than this many times the rebound before it is no bounce (a hand's lift):
  // 1.69, an apparent restitution of 1.3.
  double max_rebound_gain = 1.69;
};

class ApexLedger {
 public:
  ApexLedger(const ApexConfig& config, DetectorScene& scene, FlightFollower& follower,
             DropHost& host);

  // A new drop whose first arc is bounce `first_bounce`.
  void StartDrop(int first_bounce);
  // The current arc's apex, once due at stream time t (emit_after_apex_frames past it): the
  // scale refitted, then the peak, or the drop's end when the apex is too low for a bounce.
  void TryEmitApex(double t, int64_t utime, bool have_sample, std::vector<DetectorEvent>& ev);
  // A sample joined the current arc: bounce 0 of a release seen held goes out once the
  // first rebound has risen bounce0_rising_samples, then the current apex when due.
  void OnSampleKept(const DetectorSample& s, std::vector<DetectorEvent>& ev);
  // An impact began the current arc (the scale refitted with it): its event, the apexes of
  // the arcs before it that went unreported, bounce 0 when due.
  void OnImpact(int64_t utime, std::vector<DetectorEvent>& ev);
  // Arc j's apex as a peak (bounce 0 first, if still pending).
  void EmitPeak(size_t j, int64_t utime, std::vector<DetectorEvent>& ev);
  // The arc's apex is past by emit_after_apex_frames at time t.
  bool ApexDue(const DetectorArc& arc, double t) const;
  // Ball-centre coordinate along true down where it met the floor under arc j, from the
  // drop's impacts (a weighted line in time through their contact heights, at the apex; with
  // `both` false only those before the apex). A ball that moves towards or away from the camera
  // lands lower or higher in the picture at each bounce (the football: 25 px over 8
  // impacts), so one floor line puts every apex off by its drift.
  double FloorUnderArcPx(size_t j, bool both) const;
  // A fitted impact of this drop in metres and stream time, numbered `index`.
  BounceImpact ToBounceImpact(const FlightImpact& imp, int index) const;
  void ForgetImpact(int index);
  // The drop ends: its summary from the final refit (revised heights, flight heights,
  // restitution trend) and the end event.
  void CloseDrop(const std::string& reason, std::vector<DetectorEvent>& ev);
  // Forgets the drop's peaks and impacts.
  void ResetDrop();

  int sequence() const { return sequence_; }
  int first_bounce() const { return first_bounce_; }
  void set_first_bounce(int bounce) { first_bounce_ = bounce; }
  bool bounce0_emitted() const { return bounce0_emitted_; }
  void MarkBounce0Emitted() { bounce0_emitted_ = true; }
  bool PeakEmitted(int bounce) const;
  const std::vector<BouncePeak>& peaks() const { return peaks_; }
  const std::vector<SequenceSummary>& summaries() const { return summaries_; }
  const ApexConfig& config() const { return config_; }

 private:
  // The apexes of arcs before `end` that went unreported (seen too briefly, hidden, the arc
  // that began the drop in flight, every rebound before the scale), those that clear the
  // lowest bounce with the scale and fits as they are now: late, in bounce order.
  void EmitUnreported(size_t end, int64_t utime, std::vector<DetectorEvent>& ev);
  // The uncertainty of arc's apex measured height_m over the floor in the picture, m (the
  // arc's fit, the floor line, the scale).
  double PictureSigmaM(const DetectorArc& arc, double height_m) const;
  // What the flight times around arc j say of its apex at t_apex, measured in the picture
  // as picture_m +- picture_sigma_m.
  ApexFlightInput FlightInputFor(size_t j, double t_apex, double picture_m, double picture_sigma_m) const;
  // The drop's first arc, entered mid-flight: its apex lies within its samples.
  bool EnteredApexSeen() const;

  ApexConfig config_;
  DetectorScene& scene_;
  FlightFollower& follower_;
  DropHost& host_;
  int sequence_ = -1;
  bool bounce0_emitted_ = false;
  int first_bounce_ = 0;  // bounce number of arc 0 in this drop
  std::vector<BouncePeak> peaks_;       // this drop
  std::vector<BounceImpact> impacts_;   // this drop
  std::vector<SequenceSummary> summaries_;
};

}  // namespace bouncefit
