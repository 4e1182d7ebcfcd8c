#pragma once
// What the bounce detector reports (peaks, impacts, the calibration, a drop's end and its
// summary), and what its parts ask of the detector that composes them (DropHost).
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "detect/calibrator.h"

namespace bouncefit {

// Core-side twin of bouncefit::bounce_peak_t.
struct BouncePeak {
  int64_t utime = 0;           // capture time of the frame that made the apex certain
  int sequence = 0;            // drop sequence in this stream, from 0
  int bounce = 0;              // 0 = release height, 1 = first rebound apex, ...
  int64_t apex_utime = 0;      // fitted apex time
  double height_m = 0;         // ball bottom above the floor at the apex, metres
  double height_px = 0;        // the same in pixels along true vertical
  double height_sigma_m = 0;   // standard uncertainty
  double flight_height_m = std::numeric_limits<double>::quiet_NaN();  // g dt^2/8 (NaN: unknown)
  int64_t impact_before_utime = 0;  // impact starting this arc (0 for bounce 0)
  int64_t impact_after_utime = 0;   // impact ending it (0: not yet seen)
  int64_t emitted_utime = 0;        // stream time of the emission
};

struct BounceImpact {
  int sequence = 0;
  int index = 0;             // 1 = the impact ending the release fall, ...
  int64_t utime = 0;         // where the falling and rising arcs meet
  double speed_in_mps = 0;   // speed just before (model, drag included)
  double speed_out_mps = 0;  // speed just after
  double restitution = 0;    // speed_out / speed_in
};

struct DetectorEvent {
  enum class Kind { kCalibration, kPeak, kImpact, kSequenceEnd };
  Kind kind = Kind::kPeak;
  Calibration calibration;  // kCalibration
  BouncePeak peak;          // kPeak
  BounceImpact impact;      // kImpact
  std::string reason;       // kSequenceEnd: "rest", "lost", "broken", "end of stream"
};

// Everything known about one drop once it has ended, refitted with all its arcs.
struct SequenceSummary {
  int sequence = 0;
  std::string end_reason;
  std::vector<BouncePeak> peaks;         // as emitted
  int first_bounce = 0;                  // bounce number of arc 0 (1: began mid-bounce)
  // Arc 0 was a release from a hold seen still: bounce 0 is that release, whatever was heard
  // before it (a hand's knock, a tap: a ball held still is not bouncing).
  bool released_from_hold = false;
  std::vector<double> final_height_m;    // per arc, after the final refit
  std::vector<double> flight_height_m;   // per arc: g dt^2/8 (NaN for 0 / unknown)
  // Bounce `bounce`'s entry of those per-arc lists (NaN: no arc of this drop).
  double FinalHeightOf(int bounce) const { return OfBounce(final_height_m, bounce); }
  double FlightHeightOf(int bounce) const { return OfBounce(flight_height_m, bounce); }
  std::vector<BounceImpact> impacts;
  // Trend of restitution with impact speed: e = intercept + slope * v (NaN: < 2 impacts).
  double restitution_intercept = std::numeric_limits<double>::quiet_NaN();
  double restitution_slope_per_mps = std::numeric_limits<double>::quiet_NaN();
  Calibration calibration;

 private:
  double OfBounce(const std::vector<double>& per_arc, int bounce) const {
    const int k = bounce - first_bounce;
    return k >= 0 && k < static_cast<int>(per_arc.size()) ? per_arc[static_cast<size_t>(k)]
                                                           : std::numeric_limits<double>::quiet_NaN();
  }
};

struct DetectorSample;
struct DetectorArc;

// The drop around the parts: the BounceDetector that composes them. A part that follows a
// flight or emits an apex hands back through it what crosses into the others (the scale
// refitted, an apex due, the drop ended), so that each part keeps to its own state.
class DropHost {
 public:
  virtual ~DropHost() = default;
  // Refits the calibration with the drop's arcs (an event goes out).
  virtual void Recalibrate(int64_t utime, std::vector<DetectorEvent>& ev) = 0;
  // Ends the drop: "rest", "broken", "lost" or "end of stream".
  virtual void EndSequence(const std::string& reason, std::vector<DetectorEvent>& ev) = 0;
  // A sample joined the current arc.
  virtual void OnSampleKept(const DetectorSample& s, std::vector<DetectorEvent>& ev) = 0;
  // Stream time t went by without a sample on the current arc.
  virtual void OnNoSample(double t, int64_t utime, std::vector<DetectorEvent>& ev) = 0;
  // The follower began a new arc at an impact (its rising samples).
  virtual void OnImpactConfirmed(const DetectorSample& s, std::vector<DetectorEvent>& ev) = 0;
  // A sample for the start of a drop (no drop in flight).
  virtual void OnWaiting(const DetectorSample& s, std::vector<DetectorEvent>& ev) = 0;
  // The arc's apex is due for emission at stream time t.
  virtual bool ApexDue(const DetectorArc& arc, double t) const = 0;
  virtual bool InFlight() const = 0;
  // The drop's number in the stream, from 0.
  virtual int Sequence() const = 0;
  // Bounce number of the drop's first arc.
  virtual int FirstBounce() const = 0;
  virtual bool PeakEmitted(int bounce) const = 0;
  // Withdraws the impact numbered `index` (it was no impact).
  virtual void ForgetImpact(int index) = 0;
};

}  // namespace bouncefit
