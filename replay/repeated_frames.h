#pragma once
// Pictures a file shows twice. A frame-rate conversion (30 fps content stored at 60 fps) or a
// phone's variable-rate encoder filling its timeline repeats the previous picture: it is no new
// exposure, and delivered it would be a second sample of the ball at the same place one frame
// interval later, a stair in the trajectory that no ballistic arc fits.
//
// A repeat is a picture that does not differ from the one before it (no 2x2-pixel cell changed
// by more than a codec's requantisation, hardly any by a camera's noise, or, after a picture
// where something moved, no more than a re-encoding's requantisation), right after a picture
// that did (noise alone is a change: a camera never takes the same picture twice), in a file
// that does it regularly (3 of the last 16 pictures). A still scene never repeats for more than
// two frames; a ball turning at its apex is one frame among 16, not a pattern.
#include <opencv2/core.hpp>

#include <cstdint>

namespace bouncefit {

class RepeatedFrameFilter {
 public:
  // True when `bgr` (8-bit BGR) repeats the picture decoded before it.
  bool IsRepeat(const cv::Mat& bgr);
  int64_t repeats() const { return repeats_; }

 private:
  cv::Mat previous_;       // the previous picture, grey at half size
  int changed_cells_ = 0;  // cells the last picture that looked no repeat changed by noise or more
  int moved_cells_ = 0;    // ... and by more than a codec's requantisation
  int run_ = 0;            // pictures in a row that looked repeats
  uint16_t recent_ = 0;    // which of the last 16 pictures looked repeats (bit 0: newest)
  int64_t repeats_ = 0;
};

}  // namespace bouncefit
