#pragma once
// The image the picking window shows (the paper's Fig. 1): the first frame with the region of
// interest and the ball's box in bright green, and beside it the binary mask of the colour
// thresholds and the Cb/Y and Cr/Y histograms of the region with the thresholds marked; a few
// lines of text below. Pure drawing: the window and its events are in cli/pick_window.cc.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "capture/frame.h"
#include "track/color_pick.h"

namespace bouncefit {

struct PickViewParams {
  int max_width = 1280;   // the whole view fits in this, display pixels
  int max_height = 720;
  int panel_width = 320;  // mask and histograms column, display pixels
  int text_lines = 3;
};

// Where each part sits in the view, and the frame <-> view mapping.
struct PickLayout {
  double scale = 1;       // view pixels per frame pixel (<= 1: large frames shrink)
  cv::Size frame_size;    // frame pixels
  cv::Rect frame_area, mask_area, cb_area, cr_area, text_area;  // view pixels
  cv::Size size;          // the whole view

  cv::Point ToView(cv::Point2d frame_px) const;
  // Clamped into the frame.
  cv::Point2d ToFrame(cv::Point view_px) const;
  bool InFrame(cv::Point view_px) const { return frame_area.contains(view_px); }
};

PickLayout LayoutPickView(cv::Size frame_size, const PickViewParams& params);

// Draws the view. `preview` may be null (nothing clicked yet: frame and text only); `roi` is
// the region being dragged or chosen (empty: the whole frame).
cv::Mat ComposePickView(const Frame& frame, const PickLayout& layout, const PickPreview* preview,
                        cv::Rect roi, const std::vector<std::string>& lines);

}  // namespace bouncefit
