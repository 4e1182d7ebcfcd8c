#include "track/node/capture_node.h"

#include "msgs/lcm_bus.h"
#include "msgs/node_clock.h"
#include "msgs/lcm_log_recorder.h"

namespace bouncefit {
CaptureNode::CaptureNode(FrameSource& source, Tracker& tracker, LcmBus* bus,
                         CaptureNodeConfig config)
    : source_(source), tracker_(tracker), bus_(bus), config_(std::move(config)) {}

std::optional<BallObservation> CaptureNode::Step() {
  if (config_.max_frames > 0 && stats_.frames >= config_.max_frames) return std::nullopt;
  const int64_t t0 = SteadyMicros();
  if (start_wall_us_ < 0) start_wall_us_ = t0;
  std::optional<Frame> frame;
  try {
    frame = source_.Next();
  } catch (...) {
    stats_.dropped = source_.dropped_frames();
    stats_.wall_s = (SteadyMicros() - start_wall_us_) * 1e-6;
    throw;
  }
  const int64_t t1 = SteadyMicros();
  stats_.read_s += (t1 - t0) * 1e-6;
  stats_.dropped = source_.dropped_frames();
  if (!frame) {
    stats_.wall_s = (t1 - start_wall_us_) * 1e-6;
    return std::nullopt;
  }
  if (pace_) {
    const int64_t late = pace_(frame->utime);
    if (late > stats_.max_late_us) stats_.max_late_us = late;
  }
  if (recorder_) recorder_->Write(*frame);
  const int64_t t2 = SteadyMicros();
  BallObservation obs = tracker_.Track(*frame);
  stats_.track_s += (SteadyMicros() - t2) * 1e-6;
  obs.utime = frame->utime;
  obs.frame = frame->index;

  if (bus_ || log_) {
    const ball_box_t msg = ToBallBox(obs);
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
  if (observer_) observer_(*frame, obs);

  if (stats_.frames == 0) stats_.first_utime = frame->utime;
  stats_.last_utime = frame->utime;
  ++stats_.frames;
  if (obs.found) ++stats_.found;
  stats_.wall_s = (SteadyMicros() - start_wall_us_) * 1e-6;
  return obs;
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
  return stats_;
}

}  // namespace bouncefit
