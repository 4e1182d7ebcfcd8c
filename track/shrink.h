#pragma once
// Shrinking a frame, faster than cv::resize's INTER_AREA where that is slow.
//
// ShrinkByBlocks: by a power of two as the mean of each factor x factor block, by halving it
// again and again with bilinear steps: a bilinear halving samples exactly between four pixels,
// so each step is a 2x2 mean. Measured on this project's OpenCV (4.6), 1920x1080 BGR by 4:
// INTER_AREA 2.9 ms, the halvings 0.86 ms, the two results within 1 level (docs/PERFORMANCE.md).
// ShrinkByArea: any factor, INTER_AREA's result bit for bit.
#include <opencv2/core.hpp>

namespace bouncefit {

// dst = src shrunk by `factor` (1, 2, 4, 8, ...): size (src.cols / factor, src.rows / factor),
// each pixel the mean of its block. factor 1 copies.
void ShrinkByBlocks(const cv::Mat& src, cv::Mat* dst, int factor);

// dst = src shrunk to `size` (no larger than src) as cv::resize with INTER_AREA gives it, bit
// for bit. A non-integer factor of an 8-bit 3-channel picture (a 634 px frame to 158 px) is
// computed here: OpenCV's general area loop was half the tracking time of a 634x1750 clip
// (callgrind), four taps a pixel through a table; here each output pixel's taps are read in
// the same order and summed with the same float operations, three channels at a time.
// Whole factors but 2 x 2 (a 1080p frame by 4 or 8) are computed here too: OpenCV sums each
// block through an offset table (2.8-3.0 ms a 1080p frame), here the block's rows 16 bytes a
// step (1.2-1.6 ms), then the same float scaling and rounding. Anything else (2 x 2, OpenCV's
// own vector path; not shrinking; not BGR) goes to cv::resize.
void ShrinkByArea(const cv::Mat& src, cv::Mat* dst, cv::Size size);

}  // namespace bouncefit
