#include "detect/node/detect_node.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "msgs/lcm_bus.h"
#include "msgs/node_clock.h"

namespace bouncefit {
calibration_t ToCalibrationMsg(const Calibration& c) {
  calibration_t m{};
  m.utime = c.utime;
  m.px_per_m = c.px_per_m;
  m.px_per_m_sigma = c.px_per_m_sigma;
  m.roll_rad = c.roll_rad;
  m.roll_sigma_rad = c.roll_sigma_rad;
  m.floor_px = c.floor_px;
  m.floor_sigma_px = c.floor_sigma_px;
  m.method = c.method;
  m.samples = c.samples;
  return m;
}

bounce_peak_t ToBouncePeakMsg(const BouncePeak& p) {
  bounce_peak_t m{};
  m.utime = p.utime;
  m.sequence = p.sequence;
  m.bounce = p.bounce;
  m.apex_utime = p.apex_utime;
  m.height_m = p.height_m;
  m.height_px = p.height_px;
  m.height_sigma_m = p.height_sigma_m;
  m.flight_height_m = p.flight_height_m;
  m.impact_before_utime = p.impact_before_utime;
  m.impact_after_utime = p.impact_after_utime;
  m.emitted_utime = p.emitted_utime;
  m.revision = 0;
  m.live_bounce = p.bounce;
  m.refit_height_m = m.fused_height_m = NAN;
  return m;
}

DetectNode::DetectNode(LcmBus* bus, DetectNodeConfig config)
    : bus_(bus),
      config_(std::move(config)),
      detector_(std::make_unique<CaptureClockDetector>(config_.detector, config_.retiming)) {}

void DetectNode::Subscribe() {
  if (!bus_) throw std::logic_error("detect node: no bus to subscribe to");
  bus_->Subscribe<ball_box_t>(config_.channels.ball_box,
                              [this](const ball_box_t& box) { OnBox(box); });
}

std::vector<bounce_peak_t> RefittedPeakMsgs(const SequenceSummary& d, int64_t now_utime) {
  std::vector<bounce_peak_t> out;
  for (const BouncePeak& p : d.peaks) {
    const double refit = d.FinalHeightOf(p.bounce);
    if (!std::isfinite(refit)) continue;
    bounce_peak_t m = ToBouncePeakMsg(p);
    m.height_px = m.height_m > 0 ? m.height_px * refit / m.height_m : NAN;
    m.height_m = refit;
    m.utime = m.emitted_utime = now_utime;
    m.revision = 2;
    m.refit_height_m = refit;
    out.push_back(m);
  }
  return out;
}

std::vector<DetectorEvent> DetectNode::OnBox(const ball_box_t& box) {
  return OnObservation(FromBallBox(box));
}

std::vector<DetectorEvent> DetectNode::OnObservation(const BallObservation& obs) {
  last_box_wall_us_ = SteadyMicros();
  ++stats_.boxes;
  if (obs.found) ++stats_.found;
  std::vector<DetectorEvent> events;
  if (have_box_ && obs.utime < last_utime_) {
    // Times went backwards: a new stream (a replay restarted). Close the old one.
    events = detector_->Finish();
    for (const auto& s : detector_->detector().Summaries()) earlier_summaries_.push_back(s);
    rejected_before_ += detector_->rejected();
    detector_ = std::make_unique<CaptureClockDetector>(config_.detector, config_.retiming);
    ++stats_.stream_restarts;
  }
  have_box_ = true;
  last_utime_ = obs.utime;
  const int64_t t0 = SteadyMicros();
  auto more = detector_->Push(obs);
  events.insert(events.end(), more.begin(), more.end());
  stats_.rejected = rejected_before_ + detector_->rejected();
  stats_.detect_s += (SteadyMicros() - t0) * 1e-6;
  Publish(events);
  return events;
}

std::vector<DetectorEvent> DetectNode::Finish() {
  const auto events = detector_->Finish();
  stats_.rejected = rejected_before_ + detector_->rejected();
  Publish(events);
  return events;
}

std::vector<SequenceSummary> DetectNode::Summaries() const {
  std::vector<SequenceSummary> all = earlier_summaries_;
  for (const auto& s : detector_->detector().Summaries()) all.push_back(s);
  return all;
}

void DetectNode::Publish(const std::vector<DetectorEvent>& events) {
  for (const auto& e : events) {
    switch (e.kind) {
      case DetectorEvent::Kind::kPeak:
        ++stats_.peaks;
        if (bus_) bus_->Publish(config_.channels.bounce_peak, ToBouncePeakMsg(e.peak));
        break;
      case DetectorEvent::Kind::kCalibration:
        ++stats_.calibrations;
        if (bus_) bus_->Publish(config_.channels.calibration, ToCalibrationMsg(e.calibration));
        break;
      case DetectorEvent::Kind::kSequenceEnd:
        ++stats_.sequences_ended;
        if (bus_ && config_.publish_refits && !detector_->detector().Summaries().empty())
          for (const bounce_peak_t& m : RefittedPeakMsgs(detector_->detector().Summaries().back(), last_utime_)) {
            bus_->Publish(config_.channels.bounce_peak, m);
            ++stats_.peaks;
          }
        break;
      case DetectorEvent::Kind::kImpact:
        break;
    }
    if (on_event_) on_event_(e);
  }
}

void DetectNode::Run(const std::atomic<bool>* stop, double exit_after_idle_s) {
  if (!bus_) throw std::logic_error("detect node: no bus to run on");
  const int64_t start = SteadyMicros();
  while (!(stop && *stop)) {
    bus_->HandleOnce(50);
    if (exit_after_idle_s > 0) {
      const int64_t since = have_box_ || last_box_wall_us_ > 0 ? last_box_wall_us_ : start;
      if ((SteadyMicros() - since) * 1e-6 > exit_after_idle_s) break;
    }
  }
}

}  // namespace bouncefit
