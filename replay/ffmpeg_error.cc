#include "replay/ffmpeg_error.h"

#include <stdexcept>

extern "C" {
#include <libavutil/error.h>
#include <libavutil/log.h>
}

namespace bouncefit {

std::string FfmpegErrorText(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, buf, sizeof buf);
  return buf;
}

void ThrowIfFfmpegError(int code, const std::string& what) {
  if (code < 0) throw std::runtime_error(what + ": " + FfmpegErrorText(code));
}

void QuietFfmpegLog() { av_log_set_level(AV_LOG_QUIET); }

}  // namespace bouncefit
