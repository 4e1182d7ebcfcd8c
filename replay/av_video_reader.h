#pragma once
// A video file's pictures through FFmpeg's own libraries (libavformat, libavcodec, libswscale):
// each decoded picture as 8-bit BGR with its presentation time. OpenCV's reader does the same
// through the same libraries but sets the decoder's threads itself (one per core, on 4.6); here
// the caller chooses, so that decoding can leave a core to the tracking beside it.
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>

struct AVCodecContext;
struct AVFormatContext;
struct AVFrame;
struct AVPacket;
struct SwsContext;

namespace bouncefit {

class AvVideoReader {
 public:
  // Opens `path`'s best video stream. `threads`: the decoder's threads, 0 for one per core.
  // Throws std::runtime_error with a one-line reason when it holds no decodable video stream.
  AvVideoReader(const std::string& path, int threads);
  ~AvVideoReader();
  AvVideoReader(const AvVideoReader&) = delete;
  AvVideoReader& operator=(const AvVideoReader&) = delete;

  // The next picture in presentation order into `bgr`; `pts_ms` its presentation time since
  // the stream's start, ms (NaN when the file gives none). False at the end. Damaged packets
  // are skipped and counted (the pictures after them decode again).
  // With `luma`, also the decoder's own Y plane when the picture has one of 8 bits (planar
  // YUV, grey; not packed, RGB or deeper): a view of the decoded picture, kept alive by
  // *owner, not a copy (copying it cost the reading thread more than the tracker saved);
  // else `luma` is emptied. *limited_range: its values are 16-235.
  bool Read(cv::Mat* bgr, double* pts_ms, cv::Mat* luma = nullptr, bool* limited_range = nullptr,
            std::shared_ptr<const void>* owner = nullptr);

  double fps() const { return fps_; }                   // the stream's frame rate, 0 if unknown
  int64_t frame_count() const { return frame_count_; }  // as the container announces it, -1 if unknown
  // The turn the file asks a player to apply, clockwise degrees (0, 90, 180, 270).
  int rotation_cw_deg() const { return rotation_cw_deg_; }
  std::string codec_text() const { return codec_text_; }  // "avc1", "MJPG", ...
  int64_t damaged_packets() const { return damaged_; }

 private:
  bool ToBgr(cv::Mat* bgr);
  // picture_'s Y plane as a view of a new reference to it (see Read).
  void LumaOf(cv::Mat* luma, bool* limited_range, std::shared_ptr<const void>* owner) const;
  void Close();  // frees what is open (the constructor's failures too)

  std::string path_;
  AVFormatContext* format_ = nullptr;
  AVCodecContext* codec_ = nullptr;
  AVPacket* packet_ = nullptr;
  AVFrame* picture_ = nullptr;
  SwsContext* sws_ = nullptr;
  cv::Mat padded_;  // swscale's output, rows with room for its last block of 8 pixels
  int stream_ = -1;
  int64_t start_ = 0;          // the stream's start time, its time base
  double time_base_s_ = 0;
  bool draining_ = false;
  bool packet_held_ = false;  // packet_ read but not yet taken by the decoder
  double fps_ = 0;
  int64_t frame_count_ = -1;
  int rotation_cw_deg_ = 0;
  std::string codec_text_;
  int64_t damaged_ = 0;
};

}  // namespace bouncefit
