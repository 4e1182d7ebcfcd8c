#pragma once
// How far the whole picture moved between two frames: a hand-held camera. The finder compares
// frames to see what moved; a camera that moved 2 px makes every edge of the background
// "move" and buries the ball among them. The picture is cut into tiles; in each, the column
// and row profiles of luma are matched over a few pixels of shift. A camera that moved moves
// every textured tile the same way; a ball moves one or two of them; a blank tile says
// nothing. Only a shift most textured tiles agree on counts, so a still camera gives (0, 0)
// whatever moves in front of it.
#include <opencv2/core.hpp>

#include <vector>

namespace bouncefit {

struct PictureShiftParams {
  int tiles = 4;              // tiles per side
  int max_shift_px = 6;       // searched each way, work pixels
  double min_texture = 0.2;   // a tile's profile must vary this much (mean |step|, luma) to say anything
  int min_agreeing = 6;       // tiles that must agree on one shift of an axis ...
  double min_agreeing_share = 0.6;  // ... and this share of the tiles that said anything
};

// Each tile's column and row profiles of one frame (mean luma, mean removed), tile by tile.
struct PictureProfiles {
  cv::Size size;
  std::vector<std::vector<float>> columns, rows;
  bool empty() const { return columns.empty(); }
};

struct PictureShift {
  int dx = 0, dy = 0;  // b(x, y) shows what a showed at (x - dx, y - dy), work pixels
  int informative = 0, agreeing = 0;  // tile profiles (x and y) that said a shift, and that agree
  bool moved() const { return dx != 0 || dy != 0; }
};

// ycc: CV_8UC3 with luma in channel 0.
PictureProfiles ProfilesOf(const cv::Mat& ycc, const PictureShiftParams& params = {});
// Profiles of two frames of the same size (else no shift).
PictureShift MeasurePictureShift(const PictureProfiles& a, const PictureProfiles& b,
                                 const PictureShiftParams& params = {});

}  // namespace bouncefit
