#include "track/node/capture_node.h"

#include "msgs/lcm_bus.h"
#include "msgs/node_clock.h"
#include "msgs/lcm_log_recorder.h"

namespace bouncefit {
CaptureNode::CaptureNode(FrameSource& source, Tracker& tracker, LcmBus* bus,
                         CaptureNodeConfig config)
    : source_(source), tracker_(tracker), bus_(bus), config_(std::move(config)) {}

bool CaptureNode::Step() {
  if (ended_) return false;
  if (config_.max_frames > 0 && stats_.frames >= config_.max_frames) {
    Finish();
    return false;
  }
  const int64_t t0 = SteadyMicros();
  if (start_wall_us_ < 0) start_wall_us_ = t0;
  std::optional<Frame> frame;
  try {
    frame = source_.Next();
  } catch (...) {
    stats_.dropped = source_.dropped_frames();
    Finish();
    throw;
  }
  const int64_t t1 = SteadyMicros();
  stats_.read_s += (t1 - t0) * 1e-6;
  stats_.dropped = source_.dropped_frames();
  if (!frame) {
    Finish();
    return false;
  }
  if (pace_) {
    const int64_t late = pace_(frame->utime);
    if (late > stats_.max_late_us) stats_.max_late_us = late;
  }
  if (recorder_) recorder_->Write(*frame);
  if (stats_.frames == 0) stats_.first_utime = frame->utime;
  stats_.last_utime = frame->utime;
  ++stats_.frames;
  const int64_t t2 = SteadyMicros();
  std::vector<TrackedFrame> settled;
  try {
    settled = tracker_.Track(*frame);
  } catch (...) {
    Finish();
    throw;
  }
  stats_.track_s += (SteadyMicros() - t2) * 1e-6;
  for (const TrackedFrame& f : settled) Publish(f);
  stats_.wall_s = (SteadyMicros() - start_wall_us_) * 1e-6;
  return true;
}

void CaptureNode::Finish() {
  if (ended_) return;
  ended_ = true;
  for (const TrackedFrame& f : tracker_.Flush()) Publish(f);
  if (start_wall_us_ >= 0) stats_.wall_s = (SteadyMicros() - start_wall_us_) * 1e-6;
}

void CaptureNode::Publish(const TrackedFrame& f) {
  if (bus_ || log_) {
    const ball_box_t msg = ToBallBox(f.obs);
    buffer_.resize(static_cast<std::size_t>(msg.getEncodedSize()));
    msg.encode(buffer_.data(), 0, static_cast<int>(buffer_.size()));
    if (bus_) {
      if (bus_->raw().publish(config_.channels.ball_box, buffer_.data(),
                              static_cast<unsigned int>(buffer_.size())) == 0)
        ++stats_.published;
      else
        ++stats_.publish_failures;
    }
    if (log_) log_->Record(config_.channels.ball_box, buffer_.data(), buffer_.size(), WallMicros());
  }
  if (f.obs.found) ++stats_.found;
  if (observer_) observer_(f.frame, f.obs);
}

const CaptureStats& CaptureNode::Run(const std::atomic<bool>* stop,
                                     const std::function<void(const CaptureStats&)>& progress,
                                     double progress_period_s) {
  double next_report = progress_period_s;
  while (!(stop && stop->load())) {
    if (!Step()) break;
    if (progress && stats_.wall_s >= next_report) {
      progress(stats_);
      next_report = stats_.wall_s + progress_period_s;
    }
  }
  Finish();
  return stats_;
}

}  // namespace bouncefit
