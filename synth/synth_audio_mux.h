#pragma once
// Puts a mono sound track (16-bit PCM) into a video file written by OpenCV, with FFmpeg's
// libraries: the video packets are copied unchanged, the sound starts with the first frame.
#include <filesystem>
#include <vector>

namespace bouncefit {

// Rewrites clip in place (through a temporary next to it). Only .avi (MJPEG + PCM);
// throws std::invalid_argument for others (.mp4 holds no PCM) and
// std::runtime_error with a one-line reason when reading or writing fails.
void AddSoundTrack(const std::filesystem::path& clip, const std::vector<float>& samples,
                   int sample_rate);

}  // namespace bouncefit
