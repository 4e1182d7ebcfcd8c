#pragma once
// The bounce detector on the clock the pictures were taken on, when the stamps hold slow motion
// that no tag announces (detect/capture_clock.h), checked against the stamps by gravity.
//
// Until the stamps show slow motion (a run of slowed steps) the file is read as stamped. Where
// they first do (or where the capture period is first found after such a run: a file that
// began slowed), a reader on a clock that knows the period and reads every step as one
// reads everything again (what was emitted stands; the peaks and impacts it finds that were not
// emitted wait with its events), a second detector reads it all as stamped,
// and the two run side by side, their events held back, until each has refitted its scale on
// a free fall measured after that point. The arcs' own gravity against the ball's size
// (Calibration::gravity_over_size: 1 on the right clock, 1/s^2 on a timeline slowed s times
// and read as real, s^2 on a real one read as slowed) then chooses: the stamps only when they
// explain the ball's size by far better (a file whose encoder kept one picture in eight for a
// while: its long steps were real time). Without that evidence by the third apex, the capture
// clock stands, as a phone's slow motion asks. The chosen detector's held events go out; from
// then on it alone reads. A core with no I/O.
#include <cstdint>
#include <deque>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "detect/capture_clock.h"
#include "detect/retiming_detector.h"

namespace bouncefit {

struct ClockChoice {
  bool tested = false;        // the stamps showed slow motion and the two clocks were weighed
  bool stamped = false;       // the stamps won: their slowed steps were real time
  double capture_gravity_over_size = 0, stamped_gravity_over_size = 0;  // 0: not measured
  std::string verdict;        // one line
};

class CaptureClockDetector {
 public:
  // Throws std::invalid_argument for an invalid detector config. kStamped frame times read
  // every stamp as it is and test nothing.
  CaptureClockDetector(BounceDetectorConfig detector, FrameRetimingConfig retiming,
                       CaptureClockConfig capture = {});

  std::vector<DetectorEvent> Push(const BallObservation& obs);
  std::vector<DetectorEvent> Finish();

  const BounceDetector& detector() const { return chosen().detector(); }
  const Retiming& retiming() const { return chosen().retiming(); }
  // The capture clock the stamps were read on (a reader on the capture clock once the stamps
  // showed slow motion, else the stamps with the clock's statistics).
  const CaptureClock& capture_clock() const { return reader_->capture_clock(); }
  // The detector reads a slowed timeline on the capture clock.
  bool on_capture_clock() const { return choice_.tested && !choice_.stamped; }
  const ClockChoice& choice() const { return choice_; }
  int64_t rejected() const { return chosen().rejected(); }

 private:
  const RetimingDetector& chosen() const { return choice_.stamped && stamped_ ? *stamped_ : *reader_; }
  // Weighs the two clocks once each has measured a free fall since slow motion showed (or,
  // forced, on what there is).
  void Choose(bool forced, std::vector<DetectorEvent>* out);
  static int Peaks(const std::vector<DetectorEvent>& ev);
  // Peaks and impacts the reader emitted before slow motion showed.
  void Remember(const std::vector<DetectorEvent>& emitted);
  // Of what the reader on the capture clock found reading everything again, the peaks and
  // impacts not emitted before (and its last calibration) wait with its events.
  void HoldNotEmitted(const std::vector<DetectorEvent>& again);
  // The most steps in a row of the history at least min_slowdown of the clock's periods long.
  int LongestSlowedRunIn(const std::deque<BallObservation>& history, const CaptureClock& clock) const;

  BounceDetectorConfig config_;
  FrameRetimingConfig retiming_;
  CaptureClockConfig capture_;
  std::unique_ptr<RetimingDetector> reader_;   // on the capture clock
  std::unique_ptr<RetimingDetector> stamped_;  // as stamped, while the clocks are weighed
  std::deque<BallObservation> history_;        // what the reader read before slow motion showed
  static constexpr size_t kMaxHistory = 20000;
  bool testing_ = false, decided_ = false;
  int64_t test_from_taken_ = 0, test_from_stamp_ = 0;  // where slow motion showed, on each clock
  std::vector<DetectorEvent> held_reader_, held_stamped_;
  std::set<std::pair<int, int>> emitted_peaks_, emitted_impacts_;  // (sequence, bounce / index)
  ClockChoice choice_;
  int max_held_peaks_ = 3;
};

}  // namespace bouncefit
