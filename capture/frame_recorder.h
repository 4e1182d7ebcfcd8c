#pragma once
// Saves what a source saw to an MJPEG .avi, so a live session can be replayed later as a
// fake camera. YUYV frames are converted to BGR. Each frame's capture time and sequence
// number also go to FILE.avi.times.csv (an AVI holds only a nominal rate), which
// VideoFileSource reads back so a replayed recording keeps the camera's true timing.
#include <opencv2/videoio.hpp>

#include <cstdint>
#include <fstream>
#include <string>

#include "capture/frame.h"

namespace bouncefit {

class FrameRecorder {
 public:
  // Checks that the file can be created; the writer opens at the first frame (size known).
  // Throws std::runtime_error with a one-line reason.
  FrameRecorder(std::string path, double fps, int quality = 90);
  ~FrameRecorder();  // Close()
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  void Write(const Frame& frame);
  // Finishes the file (the AVI index is written here). Idempotent; never throws.
  void Close();

  int64_t written() const { return written_; }
  const std::string& path() const { return path_; }
  static std::string TimesPath(const std::string& video_path) { return video_path + ".times.csv"; }

 private:
  std::string path_;
  double fps_;
  int quality_;
  cv::VideoWriter writer_;
  std::ofstream times_;
  cv::Size size_;
  cv::Mat bgr_;
  int64_t written_ = 0;
  bool closed_ = false;
};

}  // namespace bouncefit
