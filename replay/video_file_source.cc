#include "replay/video_file_source.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bouncefit {
namespace {

std::string FourccText(double value) {
  const auto v = static_cast<uint32_t>(value);
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((v >> (8 * i)) & 0xff);
    if (c >= 32 && c < 127 && c != ' ') s += c;
  }
  return s.empty() ? "?" : s;
}

}  // namespace

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
                      FourccText(capture_.get(cv::CAP_PROP_FOURCC)) + " " +
                      std::to_string(info_.width) + "x" + std::to_string(info_.height) +
                      (rotation_deg_ ? ", stored turned: rotated " + std::to_string(rotation_deg_) +
                                           " deg clockwise to upright" : "") +
                      (recorded_.empty() ? ")" : ", camera times from its .times.csv)");
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
  capture_.release();
  // A core prints nothing: FFmpeg's own complaints about damaged frames stay quiet (OpenCV
  // reads this once, at its first use of FFmpeg); ours say what matters in one line. Set
  // OPENCV_FFMPEG_LOGLEVEL yourself to see them.
  ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
  // FFmpeg only: it gives the container's per-frame presentation times.
  if (!capture_.open(config_.path, cv::CAP_FFMPEG) || !capture_.isOpened())
    throw std::runtime_error("cannot open video '" + config_.path +
                             "': not a video file OpenCV/FFmpeg can read");
  // OpenCV 4.6 turns tagged frames by itself, but the wrong way round (upside down): turn
  // them ourselves. Its CAP_PROP_ORIENTATION_META is the counter-clockwise display angle.
  capture_.set(cv::CAP_PROP_ORIENTATION_AUTO, 0);
  const double meta = capture_.get(cv::CAP_PROP_ORIENTATION_META);
  const int ccw = std::isfinite(meta) ? ((static_cast<int>(std::lround(meta / 90)) % 4) + 4) % 4 : 0;
  rotation_deg_ = (360 - 90 * ccw) % 360;
  info_.nominal_fps = capture_.get(cv::CAP_PROP_FPS);
  const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
  info_.frame_count = count > 0 ? static_cast<int64_t>(count) : -1;
  pass_first_us_ = -1;
  pass_frames_ = 0;
  pass_undecodable_ = 0;
}

std::optional<Frame> VideoFileSource::Decode() {
  Frame frame;
  bool ok = false;
  // A damaged stretch (a phone's file with bad bytes) fails one read per damaged packet, and
  // the reads after it decode again: read on while the container announces more frames,
  // and count the ones lost. At a true end every further read fails at once.
  const int64_t budget = info_.frame_count > 0 ? info_.frame_count - pass_frames_ + 1 : 8;
  int64_t failed = 0;
  try {
    while (!(ok = capture_.read(frame.image) && !frame.image.empty()) && failed < budget) ++failed;
  } catch (const cv::Exception& e) {
    throw std::runtime_error("video '" + config_.path + "': decoding failed after " +
                             std::to_string(delivered_) + " frames");
  }
  if (!ok) return std::nullopt;
  undecodable_ += failed;
  pass_undecodable_ += failed;
  if (rotation_deg_ == 90) cv::rotate(frame.image, frame.image, cv::ROTATE_90_CLOCKWISE);
  if (rotation_deg_ == 180) cv::rotate(frame.image, frame.image, cv::ROTATE_180);
  if (rotation_deg_ == 270) cv::rotate(frame.image, frame.image, cv::ROTATE_90_COUNTERCLOCKWISE);
  frame.format = PixelFormat::kBgr24;
  const double pos_ms = capture_.get(cv::CAP_PROP_POS_MSEC);
  const int64_t t = std::isfinite(pos_ms) ? std::llround(pos_ms * 1000.0) : -1;
  int64_t utime;
  if (pass_first_us_ < 0) {
    // OpenCV reports a first presentation time of exactly 0 as the packet's decode time
    // (slightly negative with B-frames): the pass starts at its first frame.
    pass_first_us_ = std::max<int64_t>(t, 0);
    utime = pass_offset_us_;
  } else {
    utime = pass_offset_us_ + (t - pass_first_us_);
  }
  if (last_utime_ >= 0 && pass_frames_ > 0 && (t < 0 || utime <= last_utime_)) {
    // No usable container time: frames flushed from the decoder at the end come back as 0.
    // Continue at the last interval seen (the nominal one if none).
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

std::optional<Frame> VideoFileSource::Next() {
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
  if (config_.skip_repeats && recorded_.empty() && repeats_.IsRepeat(frame->image)) return Next();
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
  ++delivered_;
  return frame;
}

}  // namespace bouncefit
