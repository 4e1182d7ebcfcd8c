#pragma once
// The paper's picking (its Fig. 1): a pixel on the ball in the first frame gives the ball's
// colour; a region of interest crops the background away; the region's Cb and Cr histograms
// and the binary mask of the colour thresholds show the user whether that colour separates the
// ball from what surrounds it. `--pick X,Y` and `--pick-window` both take the colour from
// PickColor, so they give the same colour model. No window here (cli/pick_window.cc has it).
#include <opencv2/core.hpp>

#include <array>
#include <string>
#include <vector>

#include "capture/frame.h"
#include "track/ball_segmenter.h"
#include "track/color_model.h"

namespace bouncefit {

// The ball's colour read at one pixel.
struct PickedColor {
  // Nearly grey (white, grey or black ball): the tracker follows its brightness instead,
  // `polarity` +1 brighter than its surroundings, -1 darker.
  bool grey = false;
  int polarity = 0;
  ColorModel color;             // chroma/luma of the pixel's 5x5 neighbourhood (median)
  double ball_luma = 0;         // Y at the pixel, 0-255
  double surround_luma = 0;     // median Y of the 121 px square around it, 0-255
};

// Below this |chroma/luma| a picked pixel counts as grey.
inline constexpr double kGreyChroma = 0.06;

// Reads the colour at (x, y) (frame pixels, rounded) after a Gaussian blur of `blur_sigma_px`.
// Throws std::invalid_argument when the point lies outside the frame.
PickedColor PickColor(const Frame& frame, double x, double y, const ColorModelParams& params,
                      double blur_sigma_px);

// Histogram of the luma-normalised chroma Cb/Y or Cr/Y (the values the tracker thresholds on,
// so shading does not widen the ball's peak) over [-range, +range]; values beyond count in the
// end bins.
struct ChromaHistogram {
  static constexpr int kBins = 128;
  static constexpr double kRange = 2.0;  // chroma per luma, unitless
  std::array<int, kBins> all{};          // every pixel of the region brighter than min_luma
  std::array<int, kBins> matching{};     // ... of which match the colour model
  static double BinCentre(int bin) { return -kRange + (bin + 0.5) * (2 * kRange / kBins); }
  static int BinOf(double value);
};

// What the picking shows for one click and region.
struct PickPreview {
  cv::Point2d click;             // frame pixels
  cv::Rect roi;                 // the region, clipped to the frame, frame pixels
  int step = 1;                 // the mask's decimation (2 for regions larger than 640x480)
  PickedColor picked;
  ChromaHistogram cb, cr;       // Cb/Y and Cr/Y over the region
  double cb_low = 0, cb_high = 0, cr_low = 0, cr_high = 0;  // the thresholds (colour only)
  cv::Mat mask;                 // CV_8U, 255 = matches the colour; roi.size() / step
  std::vector<Blob> blobs;      // the mask's blobs that pass the tracker's size and shape limits
  int ball_blob = -1;           // the blob under (or nearest within its size) the click; -1: none
  double match_share = 0;       // share of the region's pixels matching, 0-1
};

// Computes the preview for a click at (x, y) and a region (empty or zero-sized: the whole
// frame), with the tracker's colour, segmentation and blur settings.
PickPreview ComputePickPreview(const Frame& frame, cv::Point2d click, cv::Rect roi,
                               const ColorModelParams& color, const SegmenterParams& segment,
                               double blur_sigma_px);

// One line for the user: the colour, its thresholds, and what the mask holds.
std::string DescribePick(const PickPreview& p);

}  // namespace bouncefit
