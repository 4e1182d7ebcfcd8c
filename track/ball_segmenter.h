#pragma once
// Colour segmentation of a region: the mask of pixels matching the ball colour and its blobs,
// each with the paper's min/max box.
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "track/color_model.h"
#include "track/split_ball.h"
#include "track/ycc_planes.h"

namespace bouncefit {

struct Blob {
  cv::Rect2f box;        // min/max of blob pixels, frame pixels
  cv::Point2f centroid;  // mean of blob pixels, frame pixels
  int pixels = 0;        // in frame pixels (scaled by step^2)
  float mean_distance = 0;  // mean colour distance of its pixels (lower is a better match)
  float nu = 0, nv = 0;     // mean normalised chroma of its pixels
  bool touches_edge = false;  // touches the region's border
  float fill = 0;        // pixels / box area (a disc is ~0.785, a square 1)
  bool joined = false;   // pieces joined across lines of another colour (track/split_ball.h)
};

// The radius of a disc of the blob's pixels.
inline double EquivalentRadius(const Blob& b) {
  return std::sqrt(std::max(b.pixels, 1) / std::numbers::pi);
}

struct SegmenterParams {
  double min_box_px = 4;    // blobs whose box side is smaller are ignored, pixels
  double max_box_px = 220;  // ... or larger, pixels
  double max_aspect = 2.6;  // longest / shortest box side (motion blur stretches the ball)
  double max_fill = 0.93;   // fuller boxes are rectangles, not balls
  double min_fill = 0.45;
  // Lines of another colour up to this wide (frame pixels) that cut the ball's colour into
  // pieces are bridged where the pieces together make one round blob (track/split_ball.h),
  // which then stands for them; 0: pieces are never joined.
  double join_gap_px = 0;
  SplitBallShape joined;
  // The picture's region (frame pixels; empty: none given): pieces its border cuts stay apart,
  // the ball's shape not all there (a ball cut by the picture's edge is found as it was).
  cv::Rect join_inside;
};

// Segments `planes` with `color`; fills *mask (CV_8U, 255 = match, and the lines bridged
// between joined pieces; planes' size) and returns the blobs that pass the size and shape
// limits.
std::vector<Blob> SegmentBlobs(const YccPlanes& planes, const ColorModel& color,
                               const SegmenterParams& params, cv::Mat* mask);

}  // namespace bouncefit
