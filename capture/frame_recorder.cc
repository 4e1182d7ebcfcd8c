#include "capture/frame_recorder.h"

#include <opencv2/imgproc.hpp>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace bouncefit {

FrameRecorder::FrameRecorder(std::string path, double fps, int quality)
    : path_(std::move(path)), fps_(fps > 0 ? fps : 30), quality_(quality) {
  if (path_.size() < 4 || path_.substr(path_.size() - 4) != ".avi")
    throw std::runtime_error("--record needs a .avi file name, got '" + path_ + "'");
  {
    std::ofstream probe(path_, std::ios::binary | std::ios::trunc);
    if (!probe) throw std::runtime_error("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  times_.open(TimesPath(path_), std::ios::trunc);
  if (!times_) throw std::runtime_error("cannot write '" + TimesPath(path_) + "'");
  times_ << "frame,utime_us,sequence\n";
}

FrameRecorder::~FrameRecorder() { Close(); }

void FrameRecorder::Write(const Frame& frame) {
  if (closed_) return;
  const cv::Mat* bgr = &frame.image;
  if (frame.format == PixelFormat::kYuyv) {
    cv::cvtColor(frame.image, bgr_, cv::COLOR_YUV2BGR_YUYV);
    bgr = &bgr_;
  }
  if (!writer_.isOpened()) {
    size_ = bgr->size();
    // OpenCV's own MJPEG AVI writer: always built in, honours the quality.
    if (!writer_.open(path_, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps_,
                      size_, {cv::VIDEOWRITER_PROP_QUALITY, quality_}))
      throw std::runtime_error("cannot record to '" + path_ + "'");
  }
  if (bgr->size() != size_)
    throw std::runtime_error("cannot record to '" + path_ + "': the frame size changed");
  writer_.write(*bgr);
  times_ << written_ << ',' << frame.utime << ',' << frame.sequence << '\n';
  ++written_;
}

void FrameRecorder::Close() {
  if (closed_) return;
  closed_ = true;
  writer_.release();
  times_.close();
}

}  // namespace bouncefit
