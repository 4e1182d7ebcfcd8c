#include "replay/video_file_source.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bouncefit {
VideoFileSourceConfig ReadAheadConfig(std::string path) {
  VideoFileSourceConfig c{std::move(path), false};
  c.read_ahead = 4;
  return c;
}

VideoFileSource::VideoFileSource(VideoFileSourceConfig config) : config_(std::move(config)) {
  const std::string& path = config_.path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw std::runtime_error("cannot open video '" + path + "': no such file");
  if (std::filesystem::is_directory(path, ec))
    throw std::runtime_error("cannot open video '" + path + "': it is a directory");
  if (!std::ifstream(path, std::ios::binary))
    throw std::runtime_error("cannot open video '" + path + "': " + std::strerror(errno));
  Open();
  // The same on every pass of a loop: read once (a reading-ahead thread reopens the file).
  rotation_deg_ = reader_->rotation_cw_deg();
  info_.nominal_fps = reader_->fps();
  info_.frame_count = reader_->frame_count();
  pending_ = Decode();
  if (!pending_)
    throw std::runtime_error("video '" + path + "' has no decodable frame (corrupt or empty?)");
  LoadTimes();
  if (!recorded_.empty()) {
    pending_->utime = 0;
    pending_->sequence = recorded_[0].sequence;
  }
  info_.width = pending_->image.cols;
  info_.height = pending_->image.rows;
  info_.description = "file " + std::filesystem::path(path).filename().string() + " (" +
                      reader_->codec_text() + " " +
                      std::to_string(info_.width) + "x" + std::to_string(info_.height) +
                      (rotation_deg_ ? ", stored turned: rotated " + std::to_string(rotation_deg_) +
                                           " deg clockwise to upright" : "") +
                      (recorded_.empty() ? ")" : ", camera times from its .times.csv)");
  if (config_.read_ahead > 0) ahead_ = std::thread([this] { ReadAhead(); });
}

VideoFileSource::~VideoFileSource() {
  if (!ahead_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  ahead_.join();
}

void VideoFileSource::ReadAhead() {
  for (;;) {
    Produced p = ProduceCounted();
    const bool last = !p.frame || p.error;
    std::unique_lock lock(mutex_);
    const auto t0 = std::chrono::steady_clock::now();
    changed_.wait(lock, [&] { return stop_ || queue_.size() < static_cast<size_t>(config_.read_ahead); });
    waits_.reader_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stop_) return;
    queue_.push_back(std::move(p));
    finished_ = last;
    changed_.notify_all();
    if (last) return;
  }
}

VideoFileSource::Produced VideoFileSource::ProduceCounted() {
  Produced p;
  try {
    p.frame = Produce();
  } catch (...) {
    p.error = std::current_exception();
  }
  p.counts = {loops_, ended_short_, repaired_, undecodable_, dropped_, repeats_.repeats()};
  return p;
}

void VideoFileSource::LoadTimes() {
  std::ifstream in(config_.path + ".times.csv");
  if (!in) return;
  std::string line;
  std::getline(in, line);
  if (line != "frame,utime_us,sequence") return;
  std::vector<Recorded> rows;
  long long frame = 0, utime = 0, sequence = 0;
  char c1 = 0, c2 = 0;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    if (!(row >> frame >> c1 >> utime >> c2 >> sequence) || c1 != ',' || c2 != ',' ||
        frame != static_cast<long long>(rows.size()) ||
        (!rows.empty() && (utime <= rows.back().utime || sequence <= rows.back().sequence)))
      return;  // not a file of ours: ignore it, use the container's times
    rows.push_back({utime, sequence});
  }
  recorded_ = std::move(rows);
}

void VideoFileSource::Open() {
  reader_.reset();
  reader_ = std::make_unique<AvVideoReader>(config_.path, config_.decoder_threads);
  pass_first_us_ = -1;
  pass_frames_ = 0;
  pass_undecodable_ = 0;
}

std::optional<Frame> VideoFileSource::Decode() {
  Frame frame;
  // A damaged stretch (a phone's file with bad bytes) loses its packets, and the pictures
  // after it decode again: the reader skips and counts them.
  double pos_ms = 0;
  const int64_t damaged_before = reader_->damaged_packets();
  const bool ok = reader_->Read(&frame.image, &pos_ms, &frame.luma, &frame.luma_limited_range, &frame.luma_owner);
  const int64_t failed = reader_->damaged_packets() - damaged_before;
  undecodable_ += failed;
  pass_undecodable_ += failed;
  if (!ok) return std::nullopt;
  if (rotation_deg_ == 90) cv::rotate(frame.image, frame.image, cv::ROTATE_90_CLOCKWISE);
  if (rotation_deg_ == 180) cv::rotate(frame.image, frame.image, cv::ROTATE_180);
  if (rotation_deg_ == 270) cv::rotate(frame.image, frame.image, cv::ROTATE_90_COUNTERCLOCKWISE);
  frame.luma_turn_cw_deg = rotation_deg_;  // turned by its reader, if it reads it
  frame.format = PixelFormat::kBgr24;
  frame.owns_image = true;  // a fresh picture each Read
  const int64_t t = std::isfinite(pos_ms) ? std::llround(pos_ms * 1000.0) : -1;
  int64_t utime;
  if (pass_first_us_ < 0) {
    // The pass starts at its first frame (a time before the stream's start counts as 0).
    pass_first_us_ = std::max<int64_t>(t, 0);
    utime = pass_offset_us_;
  } else {
    utime = pass_offset_us_ + (t - pass_first_us_);
  }
  if (last_utime_ >= 0 && pass_frames_ > 0 && (t < 0 || utime <= last_utime_)) {
    // No usable container time (none, or not after the last): continue at the last interval
    // seen (the nominal one if none).
    const int64_t step = last_step_us_ > 0 ? last_step_us_
                         : std::llround(info_.nominal_fps > 0 ? 1e6 / info_.nominal_fps : 1e6 / 30);
    utime = last_utime_ + step;
    ++repaired_;
  } else if (last_utime_ >= 0 && pass_frames_ > 0) {
    last_step_us_ = utime - last_utime_;
  }
  frame.utime = utime;
  last_utime_ = utime;
  ++pass_frames_;
  return frame;
}

VideoFileSource::QueueWaits VideoFileSource::queue_waits() const {
  std::lock_guard lock(mutex_);
  return waits_;
}

std::optional<Frame> VideoFileSource::Next() {
  Produced p;
  if (!ahead_.joinable()) {
    p = ProduceCounted();
  } else {
    std::unique_lock lock(mutex_);
    const auto t0 = std::chrono::steady_clock::now();
    changed_.wait(lock, [&] { return !queue_.empty() || finished_; });
    waits_.consumer_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (queue_.empty()) return std::nullopt;  // the end, already delivered
    p = std::move(queue_.front());
    queue_.pop_front();
    changed_.notify_all();
  }
  shown_ = p.counts;
  if (p.error) std::rethrow_exception(p.error);
  return std::move(p.frame);
}

std::optional<Frame> VideoFileSource::Produce() {
  std::optional<Frame> frame;
  if (pending_) {
    frame = std::move(pending_);
    pending_.reset();
  } else {
    frame = Decode();
    if (!frame && config_.loop && pass_frames_ > 0) {
      // The next pass starts one mean frame interval after this pass's last frame.
      const double mean_interval =
          pass_frames_ > 1 ? double(last_utime_ - pass_offset_us_) / double(pass_frames_ - 1)
                           : (info_.nominal_fps > 0 ? 1e6 / info_.nominal_fps : 1e6 / 30);
      pass_offset_us_ = last_utime_ + std::llround(mean_interval);
      ++loops_;
      Open();
      frame = Decode();
    }
  }
  if (!frame) {
    // Short by more than a container's estimate of its own length is off (a frame, or 2%
    // of a long clip): an AVI cut 10 frames short of its 216 is no rounding.
    const int64_t read = pass_frames_ + pass_undecodable_, announced = info_.frame_count;
    ended_short_ = announced > 0 && announced - read > std::max<int64_t>(2, announced / 50);
    return std::nullopt;
  }
  ++decoded_;
  // A recording of ours carries the camera's own times: every frame is an exposure.
  if (config_.skip_repeats && recorded_.empty() && repeats_.IsRepeat(frame->image)) return Produce();
  frame->index = decoded_ - 1;
  frame->sequence = decoded_ - 1;
  if (!recorded_.empty()) {
    // A recording: the camera's own times and sequence numbers, for as long as they last.
    const auto i = static_cast<std::size_t>(pass_frames_ - 1);
    if (i < recorded_.size()) {
      frame->utime = pass_offset_us_ + (recorded_[i].utime - recorded_[0].utime);
      frame->sequence = recorded_[i].sequence + loops_ * (recorded_.back().sequence + 1);
      if (i > 0) dropped_ += recorded_[i].sequence - recorded_[i - 1].sequence - 1;
      last_utime_ = frame->utime;
    }
  }
  return frame;
}

}  // namespace bouncefit
