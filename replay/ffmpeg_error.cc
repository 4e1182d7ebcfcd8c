#include "replay/ffmpeg_error.h"

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

void QuietFfmpegLog() { av_log_set_level(AV_LOG_QUIET); }

}  // namespace bouncefit
