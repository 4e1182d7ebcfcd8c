#pragma once
// The bounce detector behind the frame-time test (detect/frame_retiming.h), choosing the clock.
//
// When the ball's flight fits a faster capture rate than the stamps say (pictures dropped on
// the way to the file), the flight alone does not say which times are right: the shared
// football clip fits its re-timing 4.5x better, yet as stamped its gravity already agrees with
// the ball's size, and its heights with their flight times. The ball's size is the second,
// independent clock check (issue 13: "gravity from free fall is one scale; the ball's known
// diameter is another"). So in kAuto mode, once the test finds a re-timing, two detectors read
// the same observations, one as stamped and one re-timed; their events are held until each
// has measured a free fall, then the re-timed one is kept only if its gravity agrees with the
// ball's size (within `agree`) and the stamped one's does not. Every event of the chosen
// detector is then released in order; nothing is emitted twice. Clips whose stamps pass the
// test (all but a few) run one detector and hold nothing beyond the test's few tenths of a
// second. A core with no I/O.
#include <memory>
#include <vector>

#include "detect/bounce_detector.h"
#include "detect/frame_retiming.h"
#include "track/ball_observation.h"

namespace bouncefit {

class RetimingDetector {
 public:
  // Throws std::invalid_argument for an invalid detector config.
  RetimingDetector(BounceDetectorConfig detector, FrameRetimingConfig retiming);

  // One observation in stream order; returns the events released by it. An observation the
  // detector refuses (bad values) is counted in rejected(), never thrown.
  std::vector<DetectorEvent> Push(const BallObservation& obs);
  // End of stream: decides what is still open and closes the drop in progress.
  std::vector<DetectorEvent> Finish();

  // The detector read (while choosing: the one as stamped).
  const BounceDetector& detector() const { return detector_ ? *detector_ : *stamped_.detector; }
  // The frame-time test's verdict, with the clock chosen (decided once the choice is made).
  Retiming retiming() const;
  int64_t rejected() const { return rejected_; }

  // Gravity's scale over the ball size's within this factor: they agree.
  static constexpr double kAgree = 1.3;

 private:
  // One clock being tried: its detector's events held, and what its free fall measured.
  struct Trial {
    std::unique_ptr<BounceDetector> detector;
    std::vector<DetectorEvent> held;
    bool calibrated = false;    // a calibration came out
    double gravity_over_size = 0;  // of the first free fall measured (0: none measured)
  };

  void Feed(BounceDetector& d, const BallObservation& o, std::vector<DetectorEvent>* out);
  void FeedTrial(Trial& t, const BallObservation& o);
  // One observation released by the test, as stamped: to both trials, or to the detector on
  // the clock chosen.
  void Read(const BallObservation& o, std::vector<DetectorEvent>* events);
  void Absorb(Trial& t, std::vector<DetectorEvent> events) const;
  // Chooses when both trials are calibrated, or `at_end`; returns the chosen one's events.
  std::vector<DetectorEvent> ChooseIfKnown(bool at_end);

  BounceDetectorConfig detector_config_;
  FrameRetimer retimer_;
  // What the detector read before the test decided (the ball still, before its first moves):
  // a re-timed trial reads them too, to see the release. The last kMaxBefore only.
  std::vector<BallObservation> before_;
  static constexpr size_t kMaxBefore = 1000;
  std::unique_ptr<BounceDetector> detector_;
  bool choosing_ = false;
  Trial stamped_, retimed_;
  Retiming chosen_;  // the verdict once chosen
  bool chose_ = false;
  int64_t rejected_ = 0;
};

}  // namespace bouncefit
