#include "track/ball_extent.h"

#include <algorithm>

namespace bouncefit {

double MaxBallExtentPx(double radius_px, double speed_px_s, double frame_period_s) {
  return 2.0 * (2 * radius_px + speed_px_s * frame_period_s + std::max(4.0, 0.5 * radius_px));
}

bool BoxCanBeBall(int width, int height, double radius_px, double max_extent_px) {
  const int long_side = std::max(width, height), short_side = std::min(width, height);
  if (max_extent_px > 0 && long_side > max_extent_px) return false;
  return !(short_side < 1.2 * radius_px && long_side > 3 * radius_px);
}

}  // namespace bouncefit
