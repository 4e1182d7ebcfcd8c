#pragma once
// How far a hand-held camera has moved the picture since the stream's first frame, to a
// fraction of a pixel: the ball's track is measured against the scene, not the sensor. A
// phone held in a hand sways a few pixels a second and jitters a pixel or two a frame; a
// bounce of 5 cm is tens of pixels: uncorrected, the jitter breaks its arcs into pieces.
//
// Each frame is cut into tiles; in each, a column profile (mean luma of each few columns) and
// a row profile are matched against a reference frame's over a range of shifts, the least
// mismatch refined between its neighbours. A camera that moved moves every textured tile the
// same way; a ball moves one or two of them; a blank tile says nothing: an axis's shift is
// the median of the tiles that agree with the most common whole shift (without tiles whose
// other axis disagrees: something else moved there). The reference is replaced only once the
// picture has moved far from it, or has not been found in it for a few frames; meanwhile an
// axis not found against it is followed from the previous frame.
//
// A still camera reads exactly (0, 0): until most tiles agree on a whole shift of a profile
// step, nothing has moved (a tripod's sub-pixel noise is not fed into every track).
#include <opencv2/core.hpp>

#include <deque>
#include <vector>

#include "capture/frame.h"

namespace bouncefit {

struct CameraMotionParams {
  int tiles = 4;              // tiles per side
  double cell_pixels = 250000;  // profiles are binned in cells of bin x bin pixels, no more cells than this
  int max_shift_bins = 20;    // searched each way from the reference, bins (at most a third of a tile)
  int rekey_bins = 10;        // a new reference once the picture moved this far from it, bins
                              // (each new reference inherits its frame's error: rarely)
  int rekey_after_failures = 5;  // ... or once it was not found in this many frames in a row
  int trigger_moves = 3;      // the camera moves once this many of ...
  int trigger_frames = 8;     // ... the last this many frames measured moved by whole bins
  int still_every = 2;        // until then, every this many frames is measured (a still camera
                              // costs half: most are still; every third delayed some
                              // hand-held clips' first motion too long)
  double min_texture = 0.15;  // a tile's profile must vary this much (mean |step|, luma) to say anything
  int min_agreeing = 3;       // tiles that must agree (within a bin) on one shift of an axis ...
  double min_agreeing_share = 0.6;  // ... and this share of the tiles that said anything
};

// One frame's tile profiles: the steps of the mean luma from bin to bin, smoothed (sigma 1
// bin); NaN where the ball may be.
struct CameraProfiles {
  cv::Size size;
  int bin = 1;  // frame pixels per profile bin
  std::vector<std::vector<float>> columns, rows;
  bool empty() const { return columns.empty(); }
};

// Profiles of a BGR or YUYV frame, every pixel of each tile summed into its column and row
// sums, binned by `bin` pixels (the whole part of sqrt(pixels / cell_pixels), at least 1). The columns and
// rows of a tile that meet `ignore` (the ball) are NaN. `luma`: the frame's luma when it was
// already converted (CV_8U, frame size: cv::COLOR_BGR2GRAY of a BGR frame, the Y bytes of a
// YUYV one), else converted here.
// `luma_gain`: what a step of the given luma is in full-range luma (255 / 219 for a
// decoder's 16-235 plane). `luma_turn_cw_deg`: the luma as a file stores it, to be turned
// this much to be upright (the frame is): summed as it lies (turning it first cost as much
// as converting the frame).
CameraProfiles CameraProfilesOf(const Frame& frame, const CameraMotionParams& params = {},
                                cv::Rect2d ignore = {}, const cv::Mat* luma = nullptr,
                                double luma_gain = 1, int luma_turn_cw_deg = 0);

// The shift of b's picture against a's along one axis (b shows at x + d what a showed at x),
// in bins, with the agreement behind it.
struct AxisShift {
  bool ok = false;      // enough tiles agree
  int told = 0;         // tiles with texture enough and a clear least mismatch
  int whole = 0;        // the most common whole shift
  double bins = 0;      // refined: the median of the agreeing tiles', bins
};
struct PictureMotion {
  AxisShift x, y;
};
// How far b's picture moved against a's (same size, else nothing): each axis by the tiles
// that agree, without those whose other axis says something else moved in them.
// `expected`: the shift looked for first, bins (the camera moves little between frames).
PictureMotion MeasurePictureMotion(const CameraProfiles& a, const CameraProfiles& b,
                                   const CameraMotionParams& params = {}, cv::Point expected = {});

class CameraMotion {
 public:
  explicit CameraMotion(CameraMotionParams params = {}) : params_(params) {}
  // Measures this frame against the reference (the first frame, or a later one).
  // Tiles that meet `ignore` (the ball, where the tracker expects it) are left out. `luma`:
  // as for CameraProfilesOf.
  void Update(const Frame& frame, cv::Rect2d ignore = {}, const cv::Mat* luma = nullptr,
              double luma_gain = 1, int luma_turn_cw_deg = 0);
  // What the first frame showed at p this frame shows at p + (dx, dy), frame pixels.
  double dx() const { return moving_ ? dx_ : 0; }
  double dy() const { return moving_ ? dy_ : 0; }
  // Most tiles have agreed on a shift at least once: the camera is held, not fixed.
  bool moving() const { return moving_; }
  // Frames whose shift could not be measured (too little texture, a hand across the picture):
  // the last known shift was kept.
  long unmeasured() const { return unmeasured_; }
  // The largest |(dx, dy)| so far, frame pixels.
  double max_offset() const { return max_offset_; }

 private:
  CameraMotionParams params_;
  CameraProfiles reference_, previous_;
  std::deque<bool> recent_moves_;  // whether each of the last frames moved by a whole bin
  int failures_ = 0;               // frames in a row not measured against the reference
  double ref_dx_ = 0, ref_dy_ = 0;  // the reference frame's shift
  double dx_ = 0, dy_ = 0;
  bool moving_ = false;
  long unmeasured_ = 0;
  long frames_ = 0;
  double max_offset_ = 0;
};

}  // namespace bouncefit
