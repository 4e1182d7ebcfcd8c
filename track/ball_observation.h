#pragma once
// What the tracker reports for one frame: the core-side twin of bouncefit::ball_box_t.
#include <cstdint>

namespace bouncefit {

struct BallObservation {
  int64_t utime = 0;       // capture time of the frame, microseconds
  int64_t frame = 0;       // frame index
  bool found = false;      // false: no ball in this frame; the rest is zero
  float x = 0, y = 0, w = 0, h = 0;  // box of ball pixels (min/max, as in the paper), pixels
  float cx = 0, cy = 0;    // sub-pixel centre of the ball, pixels (image coords, y down)
  float radius_px = 0;     // radius from the round-shape fit, pixels
  int pixel_count = 0;     // ball pixels in the mask
  float aspect_ratio = 0;  // w / h
  float score = 0;         // confidence in [0, 1]
  // What the stream's first frame showed at p this frame shows at p + camera (a hand-held
  // camera; 0, 0 for a still one), pixels: the ball in the scene is (cx, cy) - camera. Set
  // whether or not the ball was found.
  float camera_dx = 0, camera_dy = 0;
};

}  // namespace bouncefit
