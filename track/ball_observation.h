#pragma once
// What the tracker reports for one frame: the core-side twin of bouncefit::ball_box_t.
#include <cmath>
#include <cstdint>

namespace bouncefit {

struct BallObservation {
  int64_t utime = 0;       // capture time of the frame, microseconds
  int64_t frame = 0;       // frame index
  bool found = false;      // false: no ball in this frame; the rest is zero
  float x = 0, y = 0, w = 0, h = 0;  // box of ball pixels (min/max, as in the paper), pixels
  // Sub-pixel centre of the ball, pixels (image coords, y down); NaN for a ball the frame's
  // border cuts that shows too little of its rim to place it (found, its box all there is).
  float cx = 0, cy = 0;
  float radius_px = 0;     // radius from the round-shape fit, pixels
  int pixel_count = 0;     // ball pixels in the mask
  float aspect_ratio = 0;  // w / h
  float score = 0;         // confidence in [0, 1]
  // What the stream's first frame showed at p this frame shows at p + camera (a hand-held
  // camera; 0, 0 for a still one), pixels: the ball in the scene is (cx, cy) - camera. Set
  // whether or not the ball was found.
  float camera_dx = 0, camera_dy = 0;
};

// The ball found and its centre placed.
inline bool CentrePlaced(const BallObservation& o) { return o.found && std::isfinite(o.cx) && std::isfinite(o.cy); }
// Where a ball found was seen: its centre, or the middle of its box when the centre is unknown.
inline double SeenX(const BallObservation& o) { return CentrePlaced(o) ? o.cx : o.x + 0.5 * o.w; }
inline double SeenY(const BallObservation& o) { return CentrePlaced(o) ? o.cy : o.y + 0.5 * o.h; }

}  // namespace bouncefit
