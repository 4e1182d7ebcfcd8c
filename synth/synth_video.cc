#include "synth/synth_video.h"

#include <fstream>
#include <stdexcept>
#include <string>

namespace bouncefit {
namespace {

std::string Lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

cv::VideoWriter OpenSynthVideo(const std::filesystem::path& path, double fps, cv::Size size,
                               int quality) {
  const std::string ext = Lower(path.extension().string());
  if (ext != ".avi" && ext != ".mp4")
    throw std::runtime_error("unsupported video extension '" + ext + "' for " +
                             path.string() + " (use .avi or .mp4)");
  {  // A clear message for a path we cannot write at all, before any codec question.
    std::ofstream probe(path, std::ios::binary | std::ios::trunc);
    if (!probe) throw std::runtime_error("cannot write " + path.string());
  }
  cv::VideoWriter writer;
  if (ext == ".avi") {
    writer.open(path.string(), cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                fps, size, {cv::VIDEOWRITER_PROP_QUALITY, quality});
    if (!writer.isOpened())
      throw std::runtime_error("OpenCV's MJPEG writer cannot open " + path.string());
    // OpenCV 4.6's MJPEG backend ignores the quality given to open(); set() takes it.
    writer.set(cv::VIDEOWRITER_PROP_QUALITY, quality);
    return writer;
  }
  if (size.width % 2 || size.height % 2)
    throw std::runtime_error(".mp4 needs an even width and height (got " +
                             std::to_string(size.width) + "x" + std::to_string(size.height) + ")");
  for (int fourcc : {cv::VideoWriter::fourcc('a', 'v', 'c', '1'),
                     cv::VideoWriter::fourcc('m', 'p', '4', 'v')}) {
    if (writer.open(path.string(), cv::CAP_FFMPEG, fourcc, fps, size)) return writer;
  }
  std::error_code ec;
  std::filesystem::remove(path, ec);
  throw std::runtime_error("cannot write .mp4: OpenCV's FFmpeg backend has no H.264 or MPEG-4 "
                           "encoder here (write .avi instead)");
}

}  // namespace bouncefit
