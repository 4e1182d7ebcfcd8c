#include "detect/retiming_detector.h"

#include <algorithm>
#include <limits>

namespace bouncefit {

RetimingDetector::RetimingDetector(BounceDetectorConfig detector, FrameRetimingConfig retiming,
                                   CaptureClockConfig capture, bool on_capture_clock)
    : detector_config_(std::move(detector)),
      capture_(capture),
      on_capture_clock_(on_capture_clock),
      retimer_(retiming),
      detector_(std::make_unique<BounceDetector>(detector_config_)) {}

void RetimingDetector::Feed(const BallObservation& o, std::vector<DetectorEvent>* out) {
  try {
    auto more = detector_->Push(retimer_.retiming().applied ? retimer_.Retimed(o) : o);
    if (out) out->insert(out->end(), more.begin(), more.end());
  } catch (const std::exception&) {
    ++rejected_;
  }
}

void RetimingDetector::OnDecided() {
  if (retimer_.retiming().applied) {
    detector_ = std::make_unique<BounceDetector>(detector_config_);
    for (const auto& o : before_) Feed(o, nullptr);  // emitted already, as stamped
  }
  before_.clear();
}

std::vector<DetectorEvent> RetimingDetector::Push(const BallObservation& stamped) {
  BallObservation obs = stamped;
  // A stamp that goes back stays as it is: the detector refuses it.
  const bool forward = stamped.utime >= last_stamp_;
  last_stamp_ = std::max(last_stamp_, stamped.utime);
  const int64_t taken = capture_.Add(stamped.utime, stamped.frame);
  if (on_capture_clock_ && forward) obs.utime = taken;
  const bool was_decided = retimer_.retiming().decided;
  const auto released = retimer_.Push(obs);
  if (!retimer_.retiming().decided) {
    before_.insert(before_.end(), released.begin(), released.end());
    while (before_.size() > kMaxBefore) before_.pop_front();
  } else if (!was_decided) {
    OnDecided();
  }
  std::vector<DetectorEvent> events;
  for (const auto& o : released) Feed(o, &events);
  return events;
}

std::vector<DetectorEvent> RetimingDetector::Finish() {
  const bool was_decided = retimer_.retiming().decided;
  const auto released = retimer_.Flush();
  if (!was_decided) OnDecided();
  std::vector<DetectorEvent> events;
  for (const auto& o : released) Feed(o, &events);
  auto more = detector_->Finish();
  events.insert(events.end(), more.begin(), more.end());
  return events;
}

}  // namespace bouncefit
