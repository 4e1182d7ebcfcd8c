#include "replay/ffmpeg_error.h"

extern "C" {
#include <libavutil/error.h>
}

namespace bouncefit {

std::string FfmpegErrorText(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, buf, sizeof buf);
  return buf;
}

}  // namespace bouncefit
