#include "replay/container_clock.h"

#include <cstdlib>
#include <cstring>

extern "C" {
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
}

#include "replay/ffmpeg_error.h"

namespace bouncefit {
namespace {

// The tags phones write for a capture rate that differs from the playback rate.
constexpr const char* kCaptureFpsTags[] = {"com.android.capture.fps",
                                           "com.apple.quicktime.capture.fps"};

double TagFps(const AVDictionary* d, std::string* tag) {
  for (const char* key : kCaptureFpsTags) {
    const AVDictionaryEntry* e = av_dict_get(d, key, nullptr, 0);
    if (!e || !e->value) continue;
    char* end = nullptr;
    const double v = std::strtod(e->value, &end);
    if (end != e->value && v > 0 && v < 100000) {
      *tag = key;
      return v;
    }
  }
  return 0;
}

}  // namespace

ContainerClock ReadContainerClock(const std::string& path) {
  ContainerClock c;
  AVFormatContext* ctx = nullptr;
  QuietFfmpegLog();
  if (avformat_open_input(&ctx, path.c_str(), nullptr, nullptr) != 0) return c;
  if (avformat_find_stream_info(ctx, nullptr) >= 0) {
    for (unsigned i = 0; i < ctx->nb_streams; ++i) {
      const AVStream* s = ctx->streams[i];
      if (s->codecpar->codec_type != AVMEDIA_TYPE_VIDEO) continue;
      const AVRational r = s->r_frame_rate.num > 0 ? s->r_frame_rate : s->avg_frame_rate;
      if (r.num > 0 && r.den > 0) c.stored_fps = av_q2d(r);
      c.capture_fps = TagFps(s->metadata, &c.tag);
      break;
    }
    if (c.capture_fps == 0) c.capture_fps = TagFps(ctx->metadata, &c.tag);
  }
  avformat_close_input(&ctx);
  return c;
}

}  // namespace bouncefit
