#pragma once
// One image from a camera or a file, with the time it was captured.
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>

namespace bouncefit {

enum class PixelFormat {
  kBgr24,  // 8-bit BGR, CV_8UC3 (decoded video files, MJPEG cameras)
  kYuyv,   // packed YUYV 4:2:2, CV_8UC2, as a V4L2 camera delivers it
};

struct Frame {
  cv::Mat image;                       // may share memory with the source: copy to keep
  // The image's memory is this frame's alone (the source never writes to it again): a
  // consumer may keep the image itself, without a copy.
  bool owns_image = false;
  PixelFormat format = PixelFormat::kBgr24;
  // The source's own luma when it had one before making `image` (a video decoder's Y plane,
  // CV_8U): what a consumer of the picture's brightness may read instead of converting
  // `image` back. Else empty. Its values as the file stores them: most often
  // 16-235 (`luma_limited_range`), else 0-255; its pixels too: a file stored turned gives it
  // unturned, `luma_turn_cw_deg` from upright (turning it is left to whoever reads it, not to
  // the thread that decodes). It may be a view of the decoder's own picture, which
  // `luma_owner` keeps alive (a copy of the Frame shares it): read it, never write it (nor
  // into a header of it: later pictures are decoded from it).
  cv::Mat luma;
  bool luma_limited_range = false;
  int luma_turn_cw_deg = 0;  // 0, 90, 180 or 270
  std::shared_ptr<const void> luma_owner;
  int64_t utime = 0;                   // capture time, microseconds (stream or driver clock)
  int64_t index = 0;                   // frames delivered so far by this source, from 0
  int64_t sequence = 0;                // source's own sequence number; gaps are dropped frames
};

}  // namespace bouncefit
