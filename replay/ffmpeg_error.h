#pragma once
// FFmpeg's error codes as text, for one-line error messages; its own log kept quiet.
#include <string>

namespace bouncefit {

std::string FfmpegErrorText(int code);

// Throws std::runtime_error "what: <FFmpeg's text>" when an FFmpeg call returned an error (< 0).
void ThrowIfFfmpegError(int code, const std::string& what);

// FFmpeg's own messages (a damaged frame's, a phone container's warnings) stay quiet, for the
// whole process: ours say what matters in one line. Every reader of FFmpeg's calls it.
void QuietFfmpegLog();

}  // namespace bouncefit
