#include "detect/retiming_detector.h"

#include <cmath>
#include <cstdio>

namespace bouncefit {

namespace {

bool Agrees(double gravity_over_size) {
  return gravity_over_size > 0 && std::abs(std::log(gravity_over_size)) <= std::log(RetimingDetector::kAgree);
}

std::string Ratio(double q) {
  if (!(q > 0)) return "not measured";
  char s[32];
  std::snprintf(s, sizeof s, "%.2fx", q);
  return s;
}

}  // namespace

RetimingDetector::RetimingDetector(BounceDetectorConfig detector, FrameRetimingConfig retiming)
    : detector_config_(std::move(detector)),
      retimer_(retiming),
      detector_(std::make_unique<BounceDetector>(detector_config_)) {}

void RetimingDetector::Feed(BounceDetector& d, const BallObservation& o, std::vector<DetectorEvent>* out) {
  try {
    auto more = d.Push(o);
    if (out) out->insert(out->end(), more.begin(), more.end());
  } catch (const std::exception&) {
    ++rejected_;
  }
}

void RetimingDetector::Absorb(Trial& t, std::vector<DetectorEvent> events) const {
  for (auto& e : events) {
    if (e.kind == DetectorEvent::Kind::kCalibration && !t.calibrated) {
      t.calibrated = true;
      if (e.calibration.FreeFallMeasured(detector_config_.calibration.max_free_fall_rel_sigma))
        t.gravity_over_size = e.calibration.gravity_over_size;
    }
    t.held.push_back(std::move(e));
  }
}

void RetimingDetector::FeedTrial(Trial& t, const BallObservation& o) {
  std::vector<DetectorEvent> events;
  Feed(*t.detector, o, &events);
  Absorb(t, std::move(events));
}

void RetimingDetector::Read(const BallObservation& o, std::vector<DetectorEvent>* events) {
  if (choosing_) {
    FeedTrial(stamped_, o);
    FeedTrial(retimed_, retimer_.Retimed(o));
  } else {
    Feed(*detector_, chosen_.applied ? retimer_.Retimed(o) : o, events);
  }
}

std::vector<DetectorEvent> RetimingDetector::Push(const BallObservation& obs) {
  const bool was_decided = retimer_.retiming().decided;
  const auto released = retimer_.Push(obs);
  const Retiming& r = retimer_.retiming();
  if (!was_decided && r.decided && r.retimed && !r.applied &&
      detector_config_.calibration.ball_diameter_m > 0) {
    // The test found a re-timing: both clocks from here, each on the whole history.
    choosing_ = true;
    stamped_.detector = std::move(detector_);
    retimed_.detector = std::make_unique<BounceDetector>(detector_config_);
    for (const auto& o : before_) Feed(*retimed_.detector, o, nullptr);  // the other emitted these
  }
  if (!r.decided) {
    before_.insert(before_.end(), released.begin(), released.end());
    if (before_.size() > kMaxBefore) before_.erase(before_.begin(), before_.end() - kMaxBefore);
  } else {
    before_.clear();
  }
  std::vector<DetectorEvent> events;
  for (const auto& o : released) Read(o, &events);
  if (choosing_) events = ChooseIfKnown(false);
  return events;
}

std::vector<DetectorEvent> RetimingDetector::Finish() {
  std::vector<DetectorEvent> events;
  for (const auto& o : retimer_.Flush()) Read(o, &events);
  if (choosing_) {
    // Both drops closed, the choice is made on what each saw.
    Absorb(stamped_, stamped_.detector->Finish());
    Absorb(retimed_, retimed_.detector->Finish());
    return ChooseIfKnown(true);
  }
  auto more = detector_->Finish();
  events.insert(events.end(), more.begin(), more.end());
  return events;
}

std::vector<DetectorEvent> RetimingDetector::ChooseIfKnown(bool at_end) {
  if (!at_end && !(stamped_.calibrated && retimed_.calibrated)) return {};
  const double qs = stamped_.gravity_over_size, qr = retimed_.gravity_over_size;
  const bool retime = Agrees(qr) && !Agrees(qs);
  Trial& kept = retime ? retimed_ : stamped_;
  detector_ = std::move(kept.detector);
  std::vector<DetectorEvent> events = std::move(kept.held);
  stamped_ = {};
  retimed_ = {};
  choosing_ = false;
  chose_ = true;

  chosen_ = retimer_.retiming();
  chosen_.applied = retime;
  char look[200];
  std::snprintf(look, sizeof look,
                "taken at %.4g fps and stamped at %.4g fps (pictures dropped): the ball's arcs fit the "
                "%.4g fps times with %.1f px of residual, %.1f px as stamped",
                chosen_.source_fps, chosen_.stamped_fps, chosen_.source_fps, chosen_.rms_retimed_px,
                chosen_.rms_as_stamped_px);
  const std::string sizes = "as stamped " + Ratio(qs) + ", re-timed " + Ratio(qr);
  if (retime)
    chosen_.verdict = std::string("frames re-timed: ") + look + "; gravity's scale then agrees with the ball's size (" +
                      sizes + ")";
  else if (Agrees(qs))
    chosen_.verdict = std::string("frame times as stamped: they look ") + look +
                      "; but as stamped gravity's scale already agrees with the ball's size (" + sizes +
                      "): --retime-frames to re-time them";
  else
    chosen_.verdict = std::string("frame times as stamped: they look ") + look +
                      "; but gravity's scale agrees with the ball's size on neither clock (" + sizes +
                      ": another ball than given?): --retime-frames to re-time them";
  return events;
}

Retiming RetimingDetector::retiming() const {
  if (chose_) return chosen_;
  Retiming r = retimer_.retiming();
  if (choosing_) r.decided = false;  // the clock is not chosen yet
  return r;
}

}  // namespace bouncefit
