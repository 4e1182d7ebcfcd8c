#include "track/ball_streak.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "track/mask_components.h"

namespace bouncefit {

BallStreak FindBallStreak(const YccPlanes& planes, const ColorModel& color, cv::Point2f expected,
                          double gate_px, double radius_px, double max_length_px,
                          const StreakParams& params) {
  BallStreak out;
  const int w = planes.y.cols, h = planes.y.rows;
  const double m = std::hypot(color.nu(), color.nv());
  if (planes.step != 1 || w < 3 || h < 3 || !(m > 1e-6) || !(radius_px > 0)) return out;
  const double du = color.nu() / m, dv = color.nv() / m;
  const double off_hue = params.max_off_hue * color.tolerance();
  const float floor = static_cast<float>(std::max(1.0, color.params().luma_floor));
  const float min_luma = static_cast<float>(color.params().min_luma);
  // Each pixel's share of the ball's chroma along its hue: the share of the exposure the ball
  // covered it (exact where ball and background are as bright; a monotone measure of it else).
  cv::Mat share(h, w, CV_32F), mask(h, w, CV_8U);
  for (int j = 0; j < h; ++j) {
    const float* py = planes.y.ptr<float>(j);
    const float* pu = planes.u.ptr<float>(j);
    const float* pv = planes.v.ptr<float>(j);
    float* ps = share.ptr<float>(j);
    uint8_t* pm = mask.ptr<uint8_t>(j);
    for (int i = 0; i < w; ++i) {
      const float inv = 1.0f / std::max(py[i], floor);
      const double nu = pu[i] * inv, nv = pv[i] * inv;
      const double along = nu * du + nv * dv;
      const double across = std::abs(-nu * dv + nv * du);
      const double s = along / m;
      const bool covered = py[i] >= min_luma && s >= params.min_share && across <= off_hue;
      ps[i] = covered ? static_cast<float>(std::min(1.0, s)) : 0.0f;
      pm[i] = covered ? 255 : 0;
    }
  }
  cv::Mat labels, stats, centroids;
  cv::Rect box;
  const int n = MaskComponents(mask, &labels, &stats, &centroids, &box);
  if (n <= 1) return out;
  const double ex = expected.x - planes.rect.x, ey = expected.y - planes.rect.y;
  int best = 0;
  double best_d = 0;
  for (int k = 1; k < n; ++k) {
    if (stats.at<int>(k, cv::CC_STAT_AREA) < 4) continue;
    const double d = std::hypot(centroids.at<double>(k, 0) - ex, centroids.at<double>(k, 1) - ey);
    if (d > gate_px) continue;
    if (best == 0 || d < best_d) best = k, best_d = d;
  }
  if (best == 0) return out;
  // Coverage-weighted moments of the component.
  double sw = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0, peak = 0;
  for (int j = 0; j < labels.rows; ++j) {
    const int* pl = labels.ptr<int>(j);
    const float* ps = share.ptr<float>(box.y + j);
    for (int i = 0; i < labels.cols; ++i) {
      if (pl[i] != best) continue;
      const double a = ps[box.x + i], x = box.x + i, y = box.y + j;
      sw += a, sx += a * x, sy += a * y, sxx += a * x * x, syy += a * y * y, sxy += a * x * y;
      peak = std::max(peak, a);
    }
  }
  if (!(sw > 0) || peak < params.min_peak) return out;
  const double cx = sx / sw, cy = sy / sw;
  const double vxx = sxx / sw - cx * cx, vyy = syy / sw - cy * cy, vxy = sxy / sw - cx * cy;
  const double mid = 0.5 * (vxx + vyy), half = std::sqrt(0.25 * (vxx - vyy) * (vxx - vyy) + vxy * vxy);
  const double major = mid + half, minor = std::max(0.0, mid - half);
  // A disc's coverage spreads r^2 / 4 along any line; a sweep of length s adds s^2 / 12 along it.
  out.width_px = 4 * std::sqrt(minor);
  out.length_px = out.width_px + std::sqrt(12 * std::max(0.0, major - minor));
  const double ang = 0.5 * std::atan2(2 * vxy, vxx - vyy);
  out.dir_x = std::cos(ang), out.dir_y = std::sin(ang);
  const int bx = stats.at<int>(best, cv::CC_STAT_LEFT), by = stats.at<int>(best, cv::CC_STAT_TOP);
  out.box = cv::Rect2f(static_cast<float>(planes.rect.x + bx), static_cast<float>(planes.rect.y + by),
                       static_cast<float>(stats.at<int>(best, cv::CC_STAT_WIDTH)),
                       static_cast<float>(stats.at<int>(best, cv::CC_STAT_HEIGHT)));
  out.pixels = stats.at<int>(best, cv::CC_STAT_AREA);
  out.cx = planes.rect.x + cx;
  out.cy = planes.rect.y + cy;
  // A ball's width across (the shares' threshold trims its thin edges: a little less than
  // the diameter), and no longer than the ball can sweep.
  const bool ball_wide = out.width_px >= 1.2 * radius_px && out.width_px <= 3 * radius_px;
  // Cut by the window's edge: its extent along the motion is not all there.
  const bool whole = bx > 0 && by > 0 && bx + stats.at<int>(best, cv::CC_STAT_WIDTH) < w &&
                     by + stats.at<int>(best, cv::CC_STAT_HEIGHT) < h;
  out.ok = ball_wide && whole && out.length_px <= max_length_px;
  return out;
}

}  // namespace bouncefit
