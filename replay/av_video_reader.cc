#include "replay/av_video_reader.h"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "replay/ffmpeg_error.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/display.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

namespace bouncefit {
namespace {

std::string TagText(uint32_t tag) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((tag >> (8 * i)) & 0xff);
    if (c >= 32 && c < 127 && c != ' ') s += c;
  }
  return s;
}

double Seconds(AVRational r) { return r.num > 0 && r.den > 0 ? av_q2d(r) : 0; }

}  // namespace

AvVideoReader::AvVideoReader(const std::string& path, int threads) : path_(path) {
  auto fail = [&](const std::string& why) {
    throw std::runtime_error("cannot open video '" + path + "': " + why);
  };
  QuietFfmpegLog();
  int r = avformat_open_input(&format_, path.c_str(), nullptr, nullptr);
  if (r < 0) fail("not a video file FFmpeg can read (" + FfmpegErrorText(r) + ")");
  if ((r = avformat_find_stream_info(format_, nullptr)) < 0) {
    avformat_close_input(&format_);
    fail("not a video file FFmpeg can read (" + FfmpegErrorText(r) + ")");
  }
  const AVCodec* decoder = nullptr;
  stream_ = av_find_best_stream(format_, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (stream_ < 0 || !decoder) {
    avformat_close_input(&format_);
    fail(stream_ == AVERROR_DECODER_NOT_FOUND ? "no decoder for its video stream" : "no video stream");
  }
  AVStream* st = format_->streams[stream_];
  codec_ = avcodec_alloc_context3(decoder);
  packet_ = av_packet_alloc();
  picture_ = av_frame_alloc();
  if (!codec_ || !packet_ || !picture_ || avcodec_parameters_to_context(codec_, st->codecpar) < 0) {
    Close();
    fail("out of memory");
  }
  codec_->pkt_timebase = st->time_base;
  codec_->thread_count = threads;
  if ((r = avcodec_open2(codec_, decoder, nullptr)) < 0) {
    Close();
    fail("its decoder does not open (" + FfmpegErrorText(r) + ")");
  }
  start_ = st->start_time == AV_NOPTS_VALUE ? 0 : st->start_time;
  time_base_s_ = Seconds(st->time_base);
  fps_ = Seconds(st->avg_frame_rate);  // the mean rate (a variable-rate phone file's too)
  if (fps_ <= 0) fps_ = Seconds(st->r_frame_rate);
  if (st->nb_frames > 0) {
    frame_count_ = st->nb_frames;
  } else {
    // No count in the header: the duration at the frame rate, as players estimate it.
    double duration_s = format_->duration > 0 ? format_->duration / double(AV_TIME_BASE) : 0;
    if (duration_s <= 0 && st->duration > 0) duration_s = st->duration * time_base_s_;
    if (duration_s > 0 && fps_ > 0) frame_count_ = std::llround(std::floor(duration_s * fps_ + 0.5));
  }
  // The display matrix holds the counter-clockwise turn a player applies.
  if (const uint8_t* m = av_stream_get_side_data(st, AV_PKT_DATA_DISPLAYMATRIX, nullptr)) {
    const double ccw = av_display_rotation_get(reinterpret_cast<const int32_t*>(m));
    if (std::isfinite(ccw)) rotation_cw_deg_ = ((-static_cast<int>(std::lround(ccw / 90)) % 4 + 4) % 4) * 90;
  }
  codec_text_ = TagText(st->codecpar->codec_tag);
  if (codec_text_.empty()) codec_text_ = avcodec_get_name(st->codecpar->codec_id);
}

AvVideoReader::~AvVideoReader() { Close(); }

void AvVideoReader::Close() {
  sws_freeContext(sws_);
  sws_ = nullptr;
  av_frame_free(&picture_);
  av_packet_free(&packet_);
  avcodec_free_context(&codec_);
  if (format_) avformat_close_input(&format_);
}

bool AvVideoReader::Read(cv::Mat* bgr, double* pts_ms, cv::Mat* luma, bool* limited_range,
                         std::shared_ptr<const void>* owner) {
  int drain_errors = 0;
  for (;;) {
    int r = avcodec_receive_frame(codec_, picture_);
    if (r == 0) {
      const int64_t ts = picture_->best_effort_timestamp;
      *pts_ms = ts == AV_NOPTS_VALUE ? std::numeric_limits<double>::quiet_NaN()
                                     : (ts - start_) * time_base_s_ * 1000.0;
      const bool ok = ToBgr(bgr);
      if (ok && luma) LumaOf(luma, limited_range, owner);
      av_frame_unref(picture_);
      if (ok) return true;
      ++damaged_;
      continue;
    }
    if (r == AVERROR_EOF) return false;
    if (r != AVERROR(EAGAIN)) {
      // A picture that failed to decode: the next ones may not. Fed the next packet first,
      // so that a decoder repeating its error cannot hold the reading in place.
      ++damaged_;
      if (draining_ && ++drain_errors > 64) return false;
      if (draining_) continue;
    } else if (draining_) {
      return false;
    }
    if (!packet_held_) {
      r = av_read_frame(format_, packet_);
      if (r < 0) {
        // The end of the file (or of what is readable of it): take what the decoder still holds.
        avcodec_send_packet(codec_, nullptr);
        draining_ = true;
        continue;
      }
    }
    packet_held_ = false;
    if (packet_->stream_index == stream_) {
      r = avcodec_send_packet(codec_, packet_);
      if (r == AVERROR(EAGAIN)) {
        packet_held_ = true;  // the decoder has pictures to give first: this packet next time
        continue;
      }
      if (r < 0) ++damaged_;
    }
    av_packet_unref(packet_);
  }
}

bool AvVideoReader::ToBgr(cv::Mat* bgr) {
  const int w = picture_->width, h = picture_->height;
  if (w <= 0 || h <= 0) return false;
  sws_ = sws_getCachedContext(sws_, w, h, static_cast<AVPixelFormat>(picture_->format), w, h,
                              AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr);
  if (!sws_) return false;
  // swscale's SIMD converters write rows in whole blocks of pixels (past the picture's
  // width) and, where the row's stride has no room for the last block, leave the last pixels
  // unwritten: convert into rows with that room, and a spare row below for the last one's
  // overrun, then copy the picture out (as OpenCV's reader does).
  padded_.create(h + 1, cv::alignSize((w + 32) * 3, 64), CV_8U);
  uint8_t* dst[4] = {padded_.data, nullptr, nullptr, nullptr};
  int dst_step[4] = {static_cast<int>(padded_.step[0]), 0, 0, 0};
  if (sws_scale(sws_, picture_->data, picture_->linesize, 0, h, dst, dst_step) != h) return false;
  cv::Mat(h, w, CV_8UC3, padded_.data, padded_.step[0]).copyTo(*bgr);
  return true;
}

void AvVideoReader::LumaOf(cv::Mat* luma, bool* limited_range, std::shared_ptr<const void>* owner) const {
  luma->release();
  owner->reset();
  const AVPixFmtDescriptor* d = av_pix_fmt_desc_get(static_cast<AVPixelFormat>(picture_->format));
  const bool has_y = d && !(d->flags & (AV_PIX_FMT_FLAG_RGB | AV_PIX_FMT_FLAG_PAL | AV_PIX_FMT_FLAG_HWACCEL)) &&
                     d->nb_components >= 1 && d->comp[0].plane == 0 && d->comp[0].step == 1 &&
                     d->comp[0].depth == 8 && d->comp[0].shift == 0 && d->comp[0].offset == 0 &&
                     picture_->linesize[0] > 0;
  if (!has_y) return;
  AVFrame* ref = av_frame_clone(picture_);  // a new reference to the same buffers
  if (!ref) return;
  *owner = std::shared_ptr<const void>(ref, [](const void* p) {
    AVFrame* f = const_cast<AVFrame*>(static_cast<const AVFrame*>(p));
    av_frame_free(&f);
  });
  *luma = cv::Mat(ref->height, ref->width, CV_8U, ref->data[0], static_cast<size_t>(ref->linesize[0]));
  const AVPixelFormat f = static_cast<AVPixelFormat>(picture_->format);
  const bool full = picture_->color_range == AVCOL_RANGE_JPEG || f == AV_PIX_FMT_YUVJ420P ||
                    f == AV_PIX_FMT_YUVJ422P || f == AV_PIX_FMT_YUVJ444P || f == AV_PIX_FMT_GRAY8;
  *limited_range = !full;
}

}  // namespace bouncefit
