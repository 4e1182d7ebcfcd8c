#include "replay/audio_file_source.h"

#include <cmath>
#include <stdexcept>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
#include <libavutil/opt.h>
#include <libswresample/swresample.h>
}

#include "replay/ffmpeg_error.h"

namespace bouncefit {
namespace {

double StreamStart(const AVStream* s) {
  return s->start_time == AV_NOPTS_VALUE ? 0.0 : s->start_time * av_q2d(s->time_base);
}

}  // namespace

struct AudioFileSource::Impl {
  std::string path;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  SwrContext* swr = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  int stream = -1;
  double zero_s = 0;        // container time of the first video frame: the video clock's 0
  double next_t_s = 0;      // where the next chunk starts when a frame has no timestamp
  bool flushing = false, done = false;

  ~Impl() {
    av_frame_free(&frame);
    av_packet_free(&packet);
    swr_free(&swr);
    avcodec_free_context(&codec);
    if (format) avformat_close_input(&format);
  }

  void Open() {
    QuietFfmpegLog();
    int rc = avformat_open_input(&format, path.c_str(), nullptr, nullptr);
    if (rc < 0) throw std::runtime_error("cannot open '" + path + "': " + FfmpegErrorText(rc));
    rc = avformat_find_stream_info(format, nullptr);
    if (rc < 0) throw std::runtime_error("cannot read '" + path + "': " + FfmpegErrorText(rc));
    const int video = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    const AVCodec* decoder = nullptr;
    stream = av_find_best_stream(format, AVMEDIA_TYPE_AUDIO, -1, -1, &decoder, 0);
    if (stream < 0) return;  // no sound: has_audio() false
    if (!decoder) throw std::runtime_error("'" + path + "': no decoder for its sound track");
    // The video's frame times (av_video_reader) count from the video stream's start time.
    zero_s = video >= 0 ? StreamStart(format->streams[video]) : 0.0;
    AVStream* s = format->streams[stream];
    next_t_s = StreamStart(s) - zero_s;
    codec = avcodec_alloc_context3(decoder);
    avcodec_parameters_to_context(codec, s->codecpar);
    codec->pkt_timebase = s->time_base;
    rc = avcodec_open2(codec, decoder, nullptr);
    if (rc < 0) throw std::runtime_error("'" + path + "': cannot decode its sound: " + FfmpegErrorText(rc));
    AVChannelLayout mono = AV_CHANNEL_LAYOUT_MONO;
    rc = swr_alloc_set_opts2(&swr, &mono, AV_SAMPLE_FMT_FLT, codec->sample_rate,
                             &codec->ch_layout, codec->sample_fmt, codec->sample_rate, 0, nullptr);
    if (rc < 0 || swr_init(swr) < 0)
      throw std::runtime_error("'" + path + "': cannot convert its sound to mono");
    for (unsigned i = 0; i < format->nb_streams; ++i)
      if (static_cast<int>(i) != stream) format->streams[i]->discard = AVDISCARD_ALL;
    packet = av_packet_alloc();
    frame = av_frame_alloc();
  }

  // Converts the decoded frame into chunk; true when it held samples.
  bool Convert(AudioChunk* chunk) {
    const int64_t pts = frame->best_effort_timestamp;
    const double t0 = pts == AV_NOPTS_VALUE
                          ? next_t_s
                          : pts * av_q2d(format->streams[stream]->time_base) - zero_s;
    chunk->t0_s = t0;
    chunk->sample_rate = codec->sample_rate;
    chunk->samples.resize(frame->nb_samples);
    uint8_t* out[1] = {reinterpret_cast<uint8_t*>(chunk->samples.data())};
    const int n = swr_convert(swr, out, frame->nb_samples,
                              const_cast<const uint8_t**>(frame->extended_data),
                              frame->nb_samples);
    av_frame_unref(frame);
    if (n <= 0) return false;
    chunk->samples.resize(n);
    next_t_s = t0 + static_cast<double>(n) / chunk->sample_rate;
    return true;
  }
};

AudioFileSource::AudioFileSource(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->Open();
}

AudioFileSource::~AudioFileSource() = default;

bool AudioFileSource::has_audio() const { return impl_->stream >= 0; }
int AudioFileSource::sample_rate() const { return has_audio() ? impl_->codec->sample_rate : 0; }

std::string AudioFileSource::Describe() const {
  if (!has_audio()) return "no sound track";
  const AVCodecContext* c = impl_->codec;
  const int ch = c->ch_layout.nb_channels;
  return std::string(c->codec->name) + " " + std::to_string(c->sample_rate) + " Hz " +
         (ch == 1 ? "mono" : ch == 2 ? "stereo" : std::to_string(ch) + " channels");
}

bool AudioFileSource::Next(AudioChunk* chunk) {
  Impl& m = *impl_;
  if (!has_audio() || m.done) return false;
  for (;;) {
    const int rc = avcodec_receive_frame(m.codec, m.frame);
    if (rc == 0) {
      if (m.Convert(chunk)) return true;
      continue;
    }
    if (rc == AVERROR_EOF) {
      m.done = true;
      return false;
    }
    if (rc != AVERROR(EAGAIN))
      throw std::runtime_error("'" + m.path + "': sound decoding failed: " + FfmpegErrorText(rc));
    if (m.flushing) {
      m.done = true;
      return false;
    }
    const int read = av_read_frame(m.format, m.packet);
    if (read < 0) {
      m.flushing = true;
      avcodec_send_packet(m.codec, nullptr);
      continue;
    }
    if (m.packet->stream_index == m.stream) {
      const int sent = avcodec_send_packet(m.codec, m.packet);
      // A damaged packet loses its few ms of sound, not the track.
      (void)sent;
    }
    av_packet_unref(m.packet);
  }
}

AudioChunk ReadAudioTrack(const std::string& path) {
  AudioFileSource source(path);
  AudioChunk all;
  if (!source.has_audio()) return all;
  all.sample_rate = source.sample_rate();
  AudioChunk c;
  bool first = true;
  while (source.Next(&c)) {
    if (first) {
      all.t0_s = c.t0_s;
      first = false;
    }
    // Place the chunk by its timestamp: fill a gap with silence, drop an overlap.
    const double at = (c.t0_s - all.t0_s) * all.sample_rate;
    const int64_t start = std::llround(at);
    const int64_t have = static_cast<int64_t>(all.samples.size());
    size_t skip = 0;
    if (start > have + 1) all.samples.resize(start, 0.0f);
    else if (start < have - 1) skip = static_cast<size_t>(std::min<int64_t>(have - start, c.samples.size()));
    all.samples.insert(all.samples.end(), c.samples.begin() + skip, c.samples.end());
  }
  return all;
}

}  // namespace bouncefit
