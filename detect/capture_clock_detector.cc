#include "detect/capture_clock_detector.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace bouncefit {

CaptureClockDetector::CaptureClockDetector(BounceDetectorConfig detector, FrameRetimingConfig retiming,
                                           CaptureClockConfig capture)
    : config_(std::move(detector)),
      retiming_(retiming),
      capture_(capture),
      reader_(std::make_unique<RetimingDetector>(config_, retiming_, capture,
                                                 retiming.mode == FrameTimes::kRetimed)) {}

int CaptureClockDetector::Peaks(const std::vector<DetectorEvent>& ev) {
  int n = 0;
  for (const auto& e : ev) n += e.kind == DetectorEvent::Kind::kPeak;
  return n;
}

std::vector<DetectorEvent> CaptureClockDetector::Push(const BallObservation& obs) {
  if (decided_ && choice_.stamped) return stamped_->Push(obs);
  const CaptureClock& before = reader_->capture_clock();
  const bool shown_before = before.shows_slow_motion();
  const int period_changes = before.period_changes();
  std::vector<DetectorEvent> out = reader_->Push(obs);
  const CaptureClock& clock = reader_->capture_clock();
  if (!testing_ && !decided_ && retiming_.mode == FrameTimes::kRetimed &&
      ((!shown_before && clock.shows_slow_motion()) ||
       (clock.period_changes() > period_changes && LongestSlowedRunIn(history_, clock) >= capture_.min_run))) {
    // Slow motion: a reader on the capture clock, every step one period, reads everything again
    // (what was emitted stands: the same times up to a ramp's first steps, or, in a file that
    // began slowed, the stamps'; what it finds anew waits with its events), and the stamps'
    // reading runs beside it.
    std::vector<int64_t> stamps;
    for (const auto& o : history_) stamps.push_back(o.utime);
    stamps.push_back(obs.utime);
    CaptureClockConfig known = capture_;
    known.known_period_s =
        CapturePeriodOfStamps(stamps, clock.capture_period_s() * 1e6, capture_) * 1e-6;
    known.constant_capture = true;
    reader_ = std::make_unique<RetimingDetector>(config_, retiming_, known, true);
    stamped_ = std::make_unique<RetimingDetector>(config_, retiming_, CaptureClockConfig{}, false);
    std::vector<DetectorEvent> again;
    for (const auto& o : history_) {
      auto ev = reader_->Push(o);
      again.insert(again.end(), ev.begin(), ev.end());
      stamped_->Push(o);  // as stamped: what was emitted
    }
    history_.clear();
    auto ev = reader_->Push(obs);
    again.insert(again.end(), ev.begin(), ev.end());
    HoldNotEmitted(again);
    testing_ = true;
    test_from_taken_ = reader_->capture_clock().last_taken();
    test_from_stamp_ = obs.utime;
    out.clear();  // the replaced reader's
  } else if (!testing_) {
    if (!decided_) {
      history_.push_back(obs);
      if (history_.size() > kMaxHistory) history_.pop_front();
      Remember(out);
    }
    return out;
  }
  held_reader_.insert(held_reader_.end(), out.begin(), out.end());
  auto more = stamped_->Push(obs);
  held_stamped_.insert(held_stamped_.end(), more.begin(), more.end());
  std::vector<DetectorEvent> released;
  Choose(false, &released);
  return released;
}

void CaptureClockDetector::Remember(const std::vector<DetectorEvent>& emitted) {
  for (const auto& e : emitted) {
    if (e.kind == DetectorEvent::Kind::kPeak) emitted_peaks_.insert({e.peak.sequence, e.peak.bounce});
    if (e.kind == DetectorEvent::Kind::kImpact) emitted_impacts_.insert({e.impact.sequence, e.impact.index});
  }
}

void CaptureClockDetector::HoldNotEmitted(const std::vector<DetectorEvent>& again) {
  const DetectorEvent* calibration = nullptr;
  for (const auto& e : again) {
    if (e.kind == DetectorEvent::Kind::kCalibration) calibration = &e;
    const bool emitted =
        (e.kind == DetectorEvent::Kind::kPeak && emitted_peaks_.count({e.peak.sequence, e.peak.bounce})) ||
        (e.kind == DetectorEvent::Kind::kImpact && emitted_impacts_.count({e.impact.sequence, e.impact.index}));
    if ((e.kind == DetectorEvent::Kind::kPeak || e.kind == DetectorEvent::Kind::kImpact) && !emitted)
      held_reader_.push_back(e);
  }
  if (calibration) held_reader_.push_back(*calibration);
}

int CaptureClockDetector::LongestSlowedRunIn(const std::deque<BallObservation>& history,
                                             const CaptureClock& clock) const {
  const double period_us = clock.capture_period_s() * 1e6;
  int run = 0, longest = 0;
  for (size_t i = 1; i < history.size(); ++i) {
    const bool one_picture = history[i].frame == history[i - 1].frame + 1 || history[i].frame <= 0;
    const bool slowed = one_picture && static_cast<double>(history[i].utime - history[i - 1].utime) >=
                                           capture_.min_slowdown * period_us;
    run = slowed ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  return longest;
}

void CaptureClockDetector::Choose(bool forced, std::vector<DetectorEvent>* out) {
  const double rel = config_.calibration.max_free_fall_rel_sigma;
  auto measured = [&](const BounceDetector& d, int64_t from) {
    return d.calibrated() && d.calibration().utime >= from && d.calibration().FreeFallMeasured(rel) &&
                   d.calibration().gravity_over_size > 0
               ? d.calibration().gravity_over_size
               : 0.0;
  };
  const double qc = measured(reader_->detector(), test_from_taken_);
  const double qs = measured(stamped_->detector(), test_from_stamp_);
  const bool both = qc > 0 && qs > 0;
  if (!both && !forced && Peaks(held_reader_) < max_held_peaks_) return;
  // The stamps only when their gravity explains the ball's size by far better.
  const double margin = std::log1p(config_.clock_tolerance);
  const bool stamps = qs > 0 && (qc == 0 || std::abs(std::log(qs)) + margin < std::abs(std::log(qc)));
  testing_ = false;
  decided_ = true;
  choice_.tested = true;
  choice_.stamped = stamps;
  choice_.capture_gravity_over_size = qc;
  choice_.stamped_gravity_over_size = qs;
  // The ratios cut (not rounded) to five characters: "1.234", "12.34".
  auto q = [](double v) { return v > 0 ? fmt::format("{:f}", v).substr(0, 5) : std::string("unmeasured"); };
  choice_.verdict = fmt::format("{}: free fall over the ball's size {} on the capture clock, {} as stamped",
                                stamps ? "the stamps' long steps are real time" : "slow motion: read on the capture clock",
                                q(qc), q(qs));
  auto& keep = stamps ? held_stamped_ : held_reader_;
  out->insert(out->end(), keep.begin(), keep.end());
  held_reader_.clear();
  held_stamped_.clear();
  if (!stamps) stamped_.reset();
}

std::vector<DetectorEvent> CaptureClockDetector::Finish() {
  std::vector<DetectorEvent> out;
  if (testing_) {
    // Each side closes its drop before the clocks are weighed on everything.
    auto a = reader_->Finish();
    held_reader_.insert(held_reader_.end(), a.begin(), a.end());
    auto b = stamped_->Finish();
    held_stamped_.insert(held_stamped_.end(), b.begin(), b.end());
    Choose(true, &out);
    return out;
  }
  return choice_.stamped ? stamped_->Finish() : reader_->Finish();
}

}  // namespace bouncefit
