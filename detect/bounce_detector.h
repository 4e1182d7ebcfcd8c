#pragma once
// Streaming bounce detection: push the tracker's observations one frame at a time, get
// events back as soon as they are certain (NOTES.md: time is an input, nothing here reads
// a clock or prints).
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
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "detect/calibrator.h"
#include "track/ball_observation.h"

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

struct BounceDetectorConfig {
  CalibratorConfig calibration;
  double emit_after_apex_frames = 1.0;  // emit this many frame periods after the fitted apex
  double gate_sigmas = 6;       // a sample this many noise sigmas off its arc is not on it
  double min_gate_px = 0.8;     // ... and at least this far
  // ... and further by this many sigmas of the scale's uncertainty, carried to the sample: a
  // first fall of a few smeared frames gives gravity to 7% (a phone's rolling shutter adds
  // more), and an arc followed with it leaves its samples with the square of the time.
  double scale_gate_sigmas = 3;
  // ... with the scale's relative uncertainty taken as at least this: a fall fits its own
  // gravity closely even when that is off (a release with a push of the hand reads gravity
  // 20-25% high, as a smeared fall can), and the first rebound must outlive it.
  double first_scale_min_rel_sigma = 0.08;
  // Times a recalibration lets the closed arcs take back their samples and fits again
  // (0: an arc keeps what it was followed with).
  int readmit_rounds = 2;
  double noise_floor_px = 0.05; // lower bound on the noise estimate
  double initial_noise_px = 0.3;  // until the first fit measures it
  // Whether the first samples make an arc: until then, the noise is taken as at least this
  // share of the ball's radius (a ball 150 px across, smeared at 24 fps, is not located to
  // 0.3 px; every length in the picture scales with its size).
  double initial_noise_radius_share = 0.01;
  double release_px = 1.5;      // a move down of at least this (and the gate) starts a drop
  double max_hold_drift = 0.5;  // a hold drifts less than this fraction of that move
  // No hold seen (the tracker found the ball only once it fell): this many samples, each
  // further down than the last, accelerating, over twice that move, start a drop whose
  // release height is the fitted vertex of the fall.
  int fall_start_samples = 5;
  // Any other arc (thrown, already bouncing): this many samples on one parabola.
  int arc_start_samples = 5;
  double min_apex_px = 1.0;     // rebounds lower than this (or 5 noise sigmas) mean rest
  // ... or lower than a flight this many frames long can show (g T^2 / 8: 2.2 cm at 30 fps,
  // 1.4 mm at 120 fps; a hop of fewer samples has no measurable apex).
  double min_flight_frames = 4;
  // A fall first seen this close to its vertex (or 2 frames) is a release whose hold was
  // missed (bounce 0 is the vertex); one seen later came from out of view.
  double unseen_release_max_s = 0.08;
  // The picture's size, px (0: not known). With it, a fall first seen later than that, its
  // vertex in the picture and nothing seen rising into it while the camera watched, is known
  // at its first impact for a release whose hold the tracker missed (a finder that sees what
  // moves finds a still ball only once it falls, later when the camera shakes).
  int image_width_px = 0, image_height_px = 0;
  double lost_s = 1.0;          // the ball unseen this long ends the drop
  double hold_window_s = 0.25;  // hold samples kept in the release arc
  // A young arc's first sample, off the arc its later samples make, is dropped: by the gate
  // when taken within straddle_frames frame periods of the impact that began the arc (it may
  // straddle it: an exposure of up to a frame, the impact's time as two young arcs place it);
  // later, only when off by off_arc_radius_share of the ball's radius (a smeared streak, a box
  // merged with a shadow), at most max_late_drops times per arc.
  double straddle_frames = 2.5;
  double off_arc_radius_share = 0.25;
  int max_late_drops = 2;
  int impact_confirm_samples = 2;  // samples off the falling arc, upwards, that make an impact
  int bounce0_rising_samples = 8;  // rising samples after the first impact before bounce 0
                                   // (release seen held; otherwise see the top comment)
  // Apex height of bounces >= 1: true = FitArcApex (model/arc_apex.h, the parabola shared
  // with the models) through the arc's samples within arc_apex_window_s of the fitted
  // vertex, drag's departure from a parabola removed; false (or too few samples there) =
  // the vertex of the drag-aware arc fitted through all the arc's samples. Both measure
  // within 0.1 mm RMS of each other on the synth presets (docs/ACCURACY.md).
  bool use_arc_apex = true;
  double arc_apex_window_s = 0.15;
  // The clock (NOTES.md, "Footage from ordinary cameras"): real seconds per second of the
  // frames' timestamps. 0 = decide: as recorded, unless the container says the file is
  // slowed (capture_slowdown_hint = capture fps / stored fps) and the ball's known size
  // confirms that factor: gravity measured on a timeline slowed s times is s^2 too small,
  // so the free-fall scale over the size scale is 1/s^2. The container's word needs less
  // of the size than the size alone would: the slowed clock is taken when it explains the
  // two scales better than the recorded one and within preset_size_error (a ball given as
  // the nearest preset: a 5 cm ball as a tennis ball's 6.7). A size that disagrees by any
  // other factor (a ball of another size than given) changes nothing but the report...
  double time_scale = 0;
  double capture_slowdown_hint = 1;
  double clock_tolerance = 0.3;  // the two scales agree within this fraction
  double preset_size_error = 2;  // ... or within this factor, with the container's word
  // ... unless the container says nothing and the disagreement is a phone's slow motion that
  // no ball given with the wrong preset explains: the presets' diameters span 6x (40 to
  // 239 mm), a timeline slowed 4x disagrees 16x, 8x 64x (a slow-motion file re-encoded, its
  // capture rate lost).
  std::vector<double> untagged_slowdowns = {4, 8};


  bool IsValid(std::string* error) const;
};

class BounceDetector {
 public:
  // Throws std::invalid_argument with a one-line message for an invalid config.
  explicit BounceDetector(BounceDetectorConfig config);

  // One frame, in capture order (utime must not go backwards: std::invalid_argument).
  std::vector<DetectorEvent> Push(const BallObservation& observation);
  // End of stream: closes the drop in progress (its summary is then in Summaries()).
  std::vector<DetectorEvent> Finish();

  const Calibration& calibration() const { return calibration_.calibration; }
  bool calibrated() const { return calibrated_; }
  const std::vector<SequenceSummary>& Summaries() const { return summaries_; }
  double noise_px() const { return sigma_; }
  double time_scale() const { return scale_; }
  double frame_period_s() const { return frame_dt_; }

 private:
  struct Sample {
    double t = 0;
    double x = 0, y = 0;
    double r = 0;
    int64_t utime = 0;
  };
  struct Arc {
    std::vector<Sample> samples;
    bool held = false;
    size_t hold_samples = 0;  // held: the first samples, still in the hand
    bool release = false;  // the first arc of a drop: a fall from rest (held seen or not)
    bool entered = false;  // the first arc of a drop, not from rest: thrown, or already
                           // in flight when first seen
    bool apex_emitted = false;
    int late_drops = 0;  // first samples dropped later than straddle_frames after the impact
    bool fit_ok = false;
    FlightArcParams fit;
    double u_sigma = 0;
  };
  enum class Phase { kWaiting, kFlight, kRest };

  void OnWaiting(const Sample& s, std::vector<DetectorEvent>& ev);
  bool ReleasedFromHold(const Sample& s, std::vector<DetectorEvent>& ev);
  bool FallFromUnseenRelease(const Sample& s, std::vector<DetectorEvent>& ev);
  bool ArcFromUnseenStart(const Sample& s, std::vector<DetectorEvent>& ev);
  bool EnteredApexSeen() const;
  // At the first impact: the drop's first arc, taken for one entered from out of view, was a
  // fall from a hold the tracker did not see (BounceDetectorConfig::image_width_px).
  bool EnteredFallWasAnUnseenRelease() const;
  void StartSequence(Arc release, const Sample& s, std::vector<DetectorEvent>& ev);
  void OnFlight(const Sample& s, std::vector<DetectorEvent>& ev);
  void OnRest(const Sample& s, std::vector<DetectorEvent>& ev);
  bool Predict(const Arc& arc, double t, double* u, double* w, double* v_down) const;
  // The arc's speed along the floor, px/s: its fit's, or before a scale from its last samples.
  double SidewaysSpeed(const Arc& arc) const;
  void RefitArc(Arc& arc);
  bool AdoptOffArcSamples(Arc& cur);
  // The release arc, young and not yet calibrated, turned away `missed` (time order) for
  // its misses: they continue its fall (below its last sample, faster and faster, free flight
  // for the ball's size), so the model lost the fall, not the ball. *fall_parabola: that
  // fall's DownParabola (dt from the last missed sample).
  bool YoungFallContinues(const Arc& cur, const std::vector<Sample>& missed,
                          Eigen::Vector3d* fall_parabola) const;
  void Recalibrate(int64_t utime, std::vector<DetectorEvent>& ev);
  // Takes a calibration fitted to the arcs as they are: the arcs' fits, the noise level.
  void ApplyCalibration(CalibrationResult res);
  // Each arc closed by a fitted impact takes back the samples seen between its impacts that
  // lie on it under the current calibration, within the gate a sample is followed with. An
  // arc is followed with the scale of the moment: a first fall's few smeared frames at 24 fps
  // measured it 25% high, and the ends of every rebound after it, off that scale, were turned
  // away or dropped; the arcs then kept their five tops, which hold their curvature least.
  // True when an arc gained a sample.
  bool ReadmitSamples();
  // free_fall: the scale just measured rests on the free fall (not on the ball's size alone).
  bool DecideClock(bool free_fall);
  // The slow-down among `slowdowns` that explains a free-fall scale q times the ball size's
  // (a timeline slowed k times reads gravity k^2 too weak), within the clock's tolerance; 0:
  // none.
  double SlowdownExplaining(double q, const std::vector<double>& slowdowns) const;
  void RescaleTime(double k);
  void ConfirmImpact(const Sample& s, std::vector<DetectorEvent>& ev);
  // At 24 fps with a long exposure, the frames either side of an impact can both show the
  // ball at the floor, a little apart: taken for an impact, a hop of two samples, and a
  // second impact. The hop is known for what it is when the rebound after it rises higher
  // than the hop could have (a bounced ball loses height at every impact): its samples are
  // dropped and its impact withdrawn, so that one impact, timed anew, joins the arcs either
  // side (its event goes out again with the same index).
  bool StraddlesItsImpact(const Arc& cur) const;
  // The impact that began the current arc, as the last calibration placed it (null: the
  // drop's first arc, or that impact not fitted).
  const FlightImpact* ImpactBeforeCurrentArc() const;
  // A fitted impact of this sequence in metres and stream time, numbered `index`.
  BounceImpact ToBounceImpact(const FlightImpact& imp, int index) const;
  void ForgetStraddlingArc();
  bool NearTheFloor(const Arc& cur) const;
  // Whether the impact the rising samples pending_up_ would confirm is one the camera could
  // not have missed had it happened: the contact, where the arc and that rebound meet (a trial
  // fit, the state unchanged), lies farther beyond every sample seen within a frame of it than
  // the ball travels from there at its modelled speed (at least half a frame's travel, for an
  // exposure straddling the contact; plus the gate), and the rebound does not rise by more
  // than the gate. A hand that moved the thing
  // tracked up, down and stopped makes such a pair (a falling arc extrapolated past where the
  // thing stopped, a "rebound" of jitter); a ball whose floor is out of view at the bottom of
  // the picture rises again and is kept.
  bool ImpactNotSeen() const;
  // The noise an arc's own samples show about its fit, px per coordinate (0: too few).
  double ArcScatter(const Arc& arc) const;
  void TryEmitApex(double t, int64_t utime, bool have_sample, std::vector<DetectorEvent>& ev);
  void EmitPeak(size_t arc_index, int64_t utime, std::vector<DetectorEvent>& ev);
  // Ball-centre coordinate along true down where it met the floor under arc j, from the
  // drop's impacts (a weighted line in time through their contact heights, at the apex; with
  // `both` false only those before the apex). A ball that moves towards or away from the camera
  // lands lower or higher in the picture at each bounce (the football: 25 px over 8
  // impacts), so one floor line puts every apex off by its drift.
  double FloorUnderArcPx(size_t j, bool both) const;
  void EndSequence(const std::string& reason, std::vector<DetectorEvent>& ev);
  double Gate() const;
  // How far a sample may lie off an arc whose model moves at v_down px/s there, gap_frames
  // after the arc's last sample: the noise gate, plus 2% of the travel (a model a little off
  // in speed is a little off in place).
  double FollowGate(double v_down, double gap_frames = 1) const;
  // How far the arc's prediction at t may be off for the uncertainty of the scale it is
  // followed with (BounceDetectorConfig::scale_gate_sigmas), px.
  double ScaleGatePx(const Arc& arc, double t) const;
  // Gate() for the fit of an arc's first samples, before the noise is measured: at least a
  // share of the ball's radius (BounceDetectorConfig::initial_noise_radius_share).
  double StartGate() const;
  // The ball's radius as seen so far (median of the recent detections), px; 0 before any.
  double RadiusPx() const;
  double MinApexPx() const;
  // bend_slowdown: the slow-down a fall's bend says (SlowdownOfBend), while the clock is
  // undecided.
  double UnseenReleaseMaxS(double bend_slowdown = 1) const;
  // The slow-down of the file's clock on which a start's bend (px/s^2 on the file's clock) is
  // free flight for the ball's size: 1, the container's, or an untagged one; 0: none (a hand's
  // curve). 1 when no size is given.
  double SlowdownOfBend(double accel_px) const;
  // Free fall at the ball's size, px/s^2 on the real clock (0: size not known).
  double SizeGravityPx() const;
  // Whether the ball was seen rising into the vertex of the fall made by the last m samples
  // held: one free flight from a sample lower than its top, beyond a hold's jitter. The
  // longest such flight's vertex time, when there is one.
  bool SeenRisingIntoFall(size_t m, double* t_vertex) const;
  // How many samples just before hold_[first] lie on the parabolas Down = cu0 + cu1 dt + cu2
  // dt^2 and Floor = cw0 + ... (dt from t_ref) within tol, back to back (gaps of 3 frames at
  // most).
  size_t OnArcBefore(size_t first, const Eigen::Vector3d& cu, const Eigen::Vector3d& cw,
                     double t_ref, double tol) const;
  // Down(t) of the samples as c0 + c1 dt + c2 dt^2, dt from the last sample's time, and the
  // fit's RMS residual (px) when asked.
  Eigen::Vector3d DownParabola(const std::vector<Sample>& run, double* rms = nullptr) const;
  double Down(const Sample& s) const;
  double Floor(const Sample& s) const;
  int64_t ToUtime(double t) const;
  std::vector<FlightArcData> ArcData() const;

  BounceDetectorConfig config_;
  Calibrator calibrator_;
  Phase phase_ = Phase::kWaiting;
  bool have_t0_ = false;
  int64_t t0_ = 0;
  int64_t last_utime_ = 0;
  double scale_ = 1;            // real seconds per stream second
  bool clock_decided_ = false;
  std::vector<double> frame_dts_;  // real seconds
  double frame_dt_ = 1.0 / 120;
  double sigma_ = 0.3;
  bool sigma_measured_ = false;
  double last_seen_t_ = 0;

  std::vector<Sample> hold_;
  std::vector<Arc> arcs_;
  std::vector<Sample> pending_up_, pending_off_;
  std::optional<Sample> last_far_;  // the previous sample, when it lay beyond the ball's reach
  int misses_ = 0;  // consecutive samples off the current arc
  bool rejudging_ = false;  // OnFlight judging a sample again after a refit of the scale
  std::vector<double> radii_;
  static constexpr size_t kSeenKept = 32;
  std::vector<Sample> seen_;  // the last samples seen, whatever became of them (ImpactNotSeen)
  static constexpr size_t kFlightSeenKept = 4096;
  std::vector<Sample> flight_seen_;  // this drop's samples in flight, kept or not (ReadmitSamples)
  int sequence_ = -1;
  bool bounce0_emitted_ = false;
  int first_bounce_ = 0;  // bounce number of arc 0 in this sequence
  // An entered first arc: the lowest sample seen shortly before it (was it at the floor?).
  std::optional<Sample> low_before_entered_;
  // ... and when the ball was last seen before it (INT64_MIN: never; INT64_MAX: not known).
  int64_t seen_before_entered_utime_ = INT64_MAX;
  std::vector<BouncePeak> peaks_;       // this sequence
  std::vector<BounceImpact> impacts_;   // this sequence
  std::vector<Sample> rest_samples_;
  int rest_moves_ = 0;

  bool calibrated_ = false;
  int calibration_sequence_ = -1;  // the drop the current calibration comes from
  CalibrationResult calibration_;
  std::vector<SequenceSummary> summaries_;
};

}  // namespace bouncefit
