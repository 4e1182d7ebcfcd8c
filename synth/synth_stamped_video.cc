#include "synth/synth_stamped_video.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libswscale/swscale.h>
}

#include "replay/ffmpeg_error.h"

namespace bouncefit {
namespace {

constexpr int kTicksPerSecond = 60000;  // MPEG-4 part 2 allows a tick of at most 1/65535 s

}  // namespace

struct StampedVideoWriter::Impl {
  std::string path;
  AVFormatContext* out = nullptr;
  AVCodecContext* enc = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* sws = nullptr;
  int64_t last_pts = -1;
  bool closed = false;

  ~Impl() {
    sws_freeContext(sws);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&enc);
    if (out) {
      if (out->pb) avio_closep(&out->pb);
      avformat_free_context(out);
    }
  }

  // Sends a frame (nullptr: flush) and writes every packet the encoder gives back.
  void Encode(AVFrame* f) {
    ThrowIfFfmpegError(avcodec_send_frame(enc, f), "encoding " + path);
    for (;;) {
      const int rc = avcodec_receive_packet(enc, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
      ThrowIfFfmpegError(rc, "encoding " + path);
      av_packet_rescale_ts(packet, enc->time_base, stream->time_base);
      packet->stream_index = stream->index;
      ThrowIfFfmpegError(av_interleaved_write_frame(out, packet), "writing " + path);
    }
  }
};

std::string StampedVideoProblem(const std::filesystem::path& path, cv::Size size) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext != ".mp4" && ext != ".mov" && ext != ".mkv")
    return "a clip with a variable frame rate must be .mp4, .mov or .mkv (got '" + ext + "')";
  if (size.width % 2 || size.height % 2)
    return "a clip with a variable frame rate needs an even width and height (got " +
           std::to_string(size.width) + "x" + std::to_string(size.height) + ")";
  return {};
}

StampedVideoWriter::StampedVideoWriter(const std::filesystem::path& path, cv::Size size,
                                       int quality)
    : impl_(std::make_unique<Impl>()) {
  if (const std::string problem = StampedVideoProblem(path, size); !problem.empty())
    throw std::runtime_error(problem);
  Impl& m = *impl_;
  m.path = path.string();
  QuietFfmpegLog();
  ThrowIfFfmpegError(avformat_alloc_output_context2(&m.out, nullptr, nullptr, m.path.c_str()),
        "cannot write " + m.path);
  const AVCodec* codec = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
  if (!codec) throw std::runtime_error("cannot write " + m.path + ": FFmpeg has no MPEG-4 encoder");
  m.stream = avformat_new_stream(m.out, nullptr);
  m.enc = avcodec_alloc_context3(codec);
  m.enc->width = size.width;
  m.enc->height = size.height;
  m.enc->pix_fmt = AV_PIX_FMT_YUV420P;
  m.enc->time_base = AVRational{1, kTicksPerSecond};
  m.enc->max_b_frames = 0;  // stamps in decoding order: every packet's dts is its pts
  m.enc->gop_size = 30;
  m.enc->flags |= AV_CODEC_FLAG_QSCALE;
  const int q = std::clamp(2 + (100 - quality) * 29 / 99, 2, 31);
  m.enc->global_quality = FF_QP2LAMBDA * q;
  if (m.out->oformat->flags & AVFMT_GLOBALHEADER) m.enc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  ThrowIfFfmpegError(avcodec_open2(m.enc, codec, nullptr), "cannot open the MPEG-4 encoder for " + m.path);
  ThrowIfFfmpegError(avcodec_parameters_from_context(m.stream->codecpar, m.enc), "writing " + m.path);
  m.stream->time_base = m.enc->time_base;
  ThrowIfFfmpegError(avio_open(&m.out->pb, m.path.c_str(), AVIO_FLAG_WRITE), "cannot write " + m.path);
  ThrowIfFfmpegError(avformat_write_header(m.out, nullptr), "cannot write " + m.path);
  m.frame = av_frame_alloc();
  m.frame->format = m.enc->pix_fmt;
  m.frame->width = size.width;
  m.frame->height = size.height;
  ThrowIfFfmpegError(av_frame_get_buffer(m.frame, 0), "allocating a frame for " + m.path);
  m.packet = av_packet_alloc();
  m.sws = sws_getContext(size.width, size.height, AV_PIX_FMT_BGR24, size.width, size.height,
                         AV_PIX_FMT_YUV420P, SWS_BICUBIC, nullptr, nullptr, nullptr);
  if (!m.sws) throw std::runtime_error("cannot convert frames for " + m.path);
}

StampedVideoWriter::~StampedVideoWriter() {
  try {
    Close();
  } catch (const std::exception&) {
  }
}

void StampedVideoWriter::Write(const cv::Mat& bgr, double t_s) {
  Impl& m = *impl_;
  if (m.closed) throw std::runtime_error(m.path + ": written after it was closed");
  if (bgr.type() != CV_8UC3 || bgr.cols != m.enc->width || bgr.rows != m.enc->height)
    throw std::runtime_error(m.path + ": a frame of another size or type");
  const int64_t pts = std::llround(t_s * kTicksPerSecond);
  if (pts <= m.last_pts)
    throw std::runtime_error(m.path + ": frame stamps must increase by at least 1/60000 s");
  m.last_pts = pts;
  ThrowIfFfmpegError(av_frame_make_writable(m.frame), "encoding " + m.path);
  const uint8_t* src[1] = {bgr.data};
  const int stride[1] = {static_cast<int>(bgr.step)};
  sws_scale(m.sws, src, stride, 0, bgr.rows, m.frame->data, m.frame->linesize);
  m.frame->pts = pts;
  m.Encode(m.frame);
}

void StampedVideoWriter::Close() {
  Impl& m = *impl_;
  if (m.closed) return;
  m.closed = true;
  m.Encode(nullptr);
  ThrowIfFfmpegError(av_write_trailer(m.out), "finishing " + m.path);
  avio_closep(&m.out->pb);
}

}  // namespace bouncefit
