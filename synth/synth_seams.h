#pragma once
// Lines painted on a ball: a basketball's channels (two great circles at right angles and two
// rings round the third axis) or a tennis ball's seam (one curve winding round it, up over two
// opposite sides and down over the other two). They cut the ball's colour into panels that a
// tracker must still see as one ball. The pattern sits on the ball, tilted to the camera, and
// turns with it about a tilted axis (BallShape::spin_rad), so the panels change from frame to
// frame as a real ball's do.
#include <array>
#include <string>

namespace bouncefit {

enum class SeamPattern { kNone, kBasketball, kTennis };
// "none", "basketball", "tennis"; throws std::invalid_argument for another name.
SeamPattern ParseSeamPattern(const std::string& name);
const char* SeamPatternName(SeamPattern pattern);

class BallSeams {
 public:
  // width_share: a line's width, share of the ball's diameter.
  BallSeams(SeamPattern pattern, double width_share);
  // The ball turned by spin_rad about its spin axis: Coverage() then reads that orientation.
  void Turn(double spin_rad);
  // How much of the pixel at normalised position (u, v) on the ball's disc (|.| <= 1, y down)
  // the lines cover, 0-1, on a ball of radius_px (their edges are a pixel wide).
  double Coverage(double u, double v, double radius_px) const;
  bool any() const { return pattern_ != SeamPattern::kNone; }

 private:
  // Distance (radii, along the surface near the line) from body point p to the nearest line.
  double Distance(const std::array<double, 3>& p) const;
  SeamPattern pattern_;
  double half_width_;  // radii
  std::array<double, 9> to_body_{1, 0, 0, 0, 1, 0, 0, 0, 1};  // camera axes -> the ball's, row-major
};

}  // namespace bouncefit
