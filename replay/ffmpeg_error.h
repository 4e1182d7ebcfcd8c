#pragma once
// FFmpeg's error codes as text, for one-line error messages.
#include <string>

namespace bouncefit {

std::string FfmpegErrorText(int code);

}  // namespace bouncefit
