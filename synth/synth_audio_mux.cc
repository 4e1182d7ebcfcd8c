#include "synth/synth_audio_mux.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
}

#include "replay/ffmpeg_error.h"

namespace bouncefit {
namespace {

// Owns the contexts so every exit path closes them.
struct Contexts {
  AVFormatContext* in = nullptr;
  AVFormatContext* out = nullptr;
  AVPacket* packet = av_packet_alloc();
  ~Contexts() {
    av_packet_free(&packet);
    if (out) {
      if (out->pb) avio_closep(&out->pb);
      avformat_free_context(out);
    }
    if (in) avformat_close_input(&in);
  }
};

}  // namespace

void AddSoundTrack(const std::filesystem::path& clip, const std::vector<float>& samples,
                   int sample_rate) {
  std::string ext = clip.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (ext != ".avi")
    throw std::invalid_argument("a synth clip with sound must be .avi (got '" + ext + "')");
  const std::string path = clip.string();
  const std::string tmp = path + ".sound" + ext;
  Contexts c;
  ThrowIfFfmpegError(avformat_open_input(&c.in, path.c_str(), nullptr, nullptr), "cannot reopen " + path);
  ThrowIfFfmpegError(avformat_find_stream_info(c.in, nullptr), "cannot read " + path);
  const int video = av_find_best_stream(c.in, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  ThrowIfFfmpegError(video, path + ": no video stream");
  ThrowIfFfmpegError(avformat_alloc_output_context2(&c.out, nullptr, nullptr, tmp.c_str()), "cannot write " + tmp);

  AVStream* vin = c.in->streams[video];
  AVStream* vout = avformat_new_stream(c.out, nullptr);
  ThrowIfFfmpegError(avcodec_parameters_copy(vout->codecpar, vin->codecpar), "copying the video stream");
  vout->codecpar->codec_tag = 0;
  vout->time_base = vin->time_base;
  vout->avg_frame_rate = vin->avg_frame_rate;
  vout->r_frame_rate = vin->r_frame_rate;

  AVStream* aout = avformat_new_stream(c.out, nullptr);
  AVCodecParameters* ap = aout->codecpar;
  ap->codec_type = AVMEDIA_TYPE_AUDIO;
  ap->codec_id = AV_CODEC_ID_PCM_S16LE;
  ap->sample_rate = sample_rate;
  av_channel_layout_default(&ap->ch_layout, 1);
  ap->format = AV_SAMPLE_FMT_S16;
  ap->bits_per_coded_sample = 16;
  ap->block_align = 2;
  ap->bit_rate = 16LL * sample_rate;
  aout->time_base = AVRational{1, sample_rate};

  ThrowIfFfmpegError(avio_open(&c.out->pb, tmp.c_str(), AVIO_FLAG_WRITE), "cannot write " + tmp);
  ThrowIfFfmpegError(avformat_write_header(c.out, nullptr), "cannot write " + tmp);

  const int64_t per_packet = 1024;
  int64_t written = 0;
  const int64_t total = static_cast<int64_t>(samples.size());
  auto write_audio_until = [&](double t_s) {
    while (written < total && written < t_s * sample_rate) {
      const int64_t n = std::min(per_packet, total - written);
      AVPacket* p = av_packet_alloc();
      ThrowIfFfmpegError(av_new_packet(p, static_cast<int>(2 * n)), "allocating a sound packet");
      auto* pcm = reinterpret_cast<int16_t*>(p->data);
      for (int64_t i = 0; i < n; ++i)
        pcm[i] = static_cast<int16_t>(std::lround(std::clamp(samples[written + i], -1.0f, 1.0f) * 32767));
      p->stream_index = aout->index;
      p->pts = p->dts = av_rescale_q(written, AVRational{1, sample_rate}, aout->time_base);
      p->duration = av_rescale_q(n, AVRational{1, sample_rate}, aout->time_base);
      const int rc = av_interleaved_write_frame(c.out, p);
      av_packet_free(&p);
      ThrowIfFfmpegError(rc, "writing sound to " + tmp);
      written += n;
    }
  };
  const double v0 = vin->start_time == AV_NOPTS_VALUE ? 0 : vin->start_time * av_q2d(vin->time_base);
  while (av_read_frame(c.in, c.packet) >= 0) {
    if (c.packet->stream_index != video) {
      av_packet_unref(c.packet);
      continue;
    }
    const int64_t ts = c.packet->dts != AV_NOPTS_VALUE ? c.packet->dts : c.packet->pts;
    if (ts != AV_NOPTS_VALUE) write_audio_until(ts * av_q2d(vin->time_base) - v0);
    av_packet_rescale_ts(c.packet, vin->time_base, vout->time_base);
    c.packet->stream_index = vout->index;
    c.packet->pos = -1;
    ThrowIfFfmpegError(av_interleaved_write_frame(c.out, c.packet), "writing video to " + tmp);
  }
  write_audio_until(1e300);
  ThrowIfFfmpegError(av_write_trailer(c.out), "finishing " + tmp);
  avio_closep(&c.out->pb);
  std::filesystem::rename(tmp, clip);
}

}  // namespace bouncefit
