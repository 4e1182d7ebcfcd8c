#pragma once
// A video file whose frames carry stamps of their own (a variable frame rate), written through
// FFmpeg's libraries: OpenCV's VideoWriter stamps every frame one period after the last. MPEG-4
// part 2 (no B-frames) in .mp4, .mov or .mkv, on a 1/60000 s tick (.mkv rounds to its 1 ms
// tick), with no capture-rate tag.
#include <opencv2/core.hpp>

#include <filesystem>
#include <memory>
#include <string>

namespace bouncefit {

// Empty when `path` (.mp4, .mov or .mkv, any case) and `size` (even width and height) can be
// written with stamps of their own, else a one-line reason.
std::string StampedVideoProblem(const std::filesystem::path& path, cv::Size size);

class StampedVideoWriter {
 public:
  // quality: 1-100 (100: the finest quantiser). Throws std::runtime_error (one line) for an
  // unsupported extension, an odd frame size or a file that cannot be written.
  StampedVideoWriter(const std::filesystem::path& path, cv::Size size, int quality);
  ~StampedVideoWriter();
  StampedVideoWriter(const StampedVideoWriter&) = delete;
  StampedVideoWriter& operator=(const StampedVideoWriter&) = delete;

  // An 8-bit BGR frame stamped t_s seconds after the first (strictly increasing).
  void Write(const cv::Mat& bgr, double t_s);
  // Flushes the encoder and writes the trailer (the destructor does it when not called).
  void Close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bouncefit
