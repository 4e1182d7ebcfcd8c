#pragma once
// Shrinking a frame by a power of two as the mean of each factor x factor block (what
// cv::INTER_AREA gives), by halving it again and again with bilinear steps: a bilinear halving
// samples exactly between four pixels, so each step is a 2x2 mean. Measured on this project's
// OpenCV (4.6), 1920x1080 BGR by 4: INTER_AREA 2.9 ms, the halvings 0.86 ms, the two results
// within 1 level (docs/PERFORMANCE.md).
#include <opencv2/core.hpp>

namespace bouncefit {

// dst = src shrunk by `factor` (1, 2, 4, 8, ...): size (src.cols / factor, src.rows / factor),
// each pixel the mean of its block. factor 1 copies.
void ShrinkByBlocks(const cv::Mat& src, cv::Mat* dst, int factor);

}  // namespace bouncefit
