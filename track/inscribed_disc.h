#pragma once
// The largest disc inside a blob: where a ball run together with a patch of its own colour
// (a poster behind a close-up ball) still sits. The merged blob's centroid lies between the
// two; the disc's centre lies in the ball when the ball is the roundest, widest part of it.
#include <opencv2/core.hpp>

namespace bouncefit {

struct InscribedDisc {
  bool ok = false;
  double cx = 0, cy = 0, r = 0;  // mask pixels
};

// The largest disc inside the set pixels (non-zero) of `mask` (CV_8U) within `box` (mask
// pixels). A side of `box` marked open goes on beyond the picture (the frame's border cuts the
// ball there): the disc may reach across it.
InscribedDisc LargestInscribedDisc(const cv::Mat& mask, cv::Rect box, bool open_left, bool open_top,
                                   bool open_right, bool open_bottom);

}  // namespace bouncefit
