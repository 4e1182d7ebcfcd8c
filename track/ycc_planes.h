#pragma once
// A rectangle of a frame as three float planes: luma Y (0-255) and the chroma differences
// U = Cb-128 and V = Cr-128 (full-range BT.601, as JPEG/MJPEG decoders give them). BGR frames
// are converted per pixel; YUYV frames are read straight from their bytes (limited range,
// rescaled), chroma interpolated to every pixel: no RGB round trip.
#include <opencv2/core.hpp>

#include "capture/frame.h"

namespace bouncefit {

struct YccPlanes {
  cv::Rect rect;       // the region in frame pixels (full-resolution coordinates)
  int step = 1;        // decimation: 1 = every pixel, 2 = 2x2 averaged
  cv::Mat y, u, v;     // CV_32F, rect.height/step x rect.width/step
};

// Fills *out for `rect` (clipped to the frame) with decimation `step` (1 or 2), then blurs each
// plane with a Gaussian of `blur_sigma_px` (in output pixels; <= 0: no blur).
// Throws std::invalid_argument for an image that does not match its PixelFormat.
void ExtractYcc(const Frame& frame, cv::Rect rect, int step, double blur_sigma_px,
                YccPlanes* out);

// Throws std::invalid_argument when the image does not match its PixelFormat.
void CheckFrameFormat(const Frame& frame);

// Full-range BT.601 of one BGR colour (0-255): y, u = cb-128, v = cr-128.
void BgrToYuv(double b, double g, double r, double* y, double* u, double* v);
// Inverse of BgrToYuv (clamped to 0-255).
void YuvToBgr(double y, double u, double v, double* b, double* g, double* r);

// Frame size in pixels for either format.
cv::Size FramePixelSize(const Frame& frame);

}  // namespace bouncefit
