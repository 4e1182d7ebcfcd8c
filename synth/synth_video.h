#pragma once
// Opens the video file a synth clip is written to: .avi as MJPEG (OpenCV's own encoder, no
// ffmpeg needed), .mp4 through OpenCV's FFmpeg backend when it has an MP4 encoder.
#include <opencv2/videoio.hpp>

#include <filesystem>

namespace bouncefit {

// quality: JPEG quality 1-100 for .avi (ignored for .mp4). Throws std::runtime_error with a
// one-line message for another extension, an unwritable path, or .mp4 without an encoder.
cv::VideoWriter OpenSynthVideo(const std::filesystem::path& path, double fps, cv::Size size,
                               int quality);

}  // namespace bouncefit
