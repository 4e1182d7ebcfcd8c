#include "track/circle_fit.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace bouncefit {

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Circle through three points; false when they are (nearly) collinear.
bool Circle3(const EdgePoint& a, const EdgePoint& b, const EdgePoint& c, double* cx, double* cy,
             double* r) {
  const double bx = b.x - a.x, by = b.y - a.y, qx = c.x - a.x, qy = c.y - a.y;
  const double d = 2 * (bx * qy - by * qx);
  if (std::abs(d) < 1e-9) return false;
  const double b2 = bx * bx + by * by, q2 = qx * qx + qy * qy;
  const double ux = (qy * b2 - by * q2) / d, uy = (bx * q2 - qx * b2) / d;
  *cx = a.x + ux;
  *cy = a.y + uy;
  *r = std::hypot(ux, uy);
  return true;
}

int CountInliers(const std::vector<EdgePoint>& pts, double cx, double cy, double r, double tol) {
  int n = 0;
  for (const auto& p : pts) n += std::abs(std::hypot(p.x - cx, p.y - cy) - r) < tol;
  return n;
}

// Replaces the start (cx, cy, r) by the circle through three rim points spread 120 degrees
// apart that agrees with the most points, if it clearly beats the start: a consensus start lets the
// robust fit drop a deformed or shaded arc instead of settling halfway.
void ConsensusStart(const std::vector<EdgePoint>& pts, double* cx, double* cy, double* r) {
  const size_t n = pts.size();
  if (n < 12) return;
  const double tol = std::max(0.35, 0.04 * *r);
  const int start = CountInliers(pts, *cx, *cy, *r, tol);
  int best = start;
  double bx = *cx, by = *cy, br = *r;
  for (size_t k = 0; k < n / 3; ++k) {
    double x, y, rr;
    if (!Circle3(pts[k], pts[k + n / 3], pts[k + 2 * n / 3], &x, &y, &rr)) continue;
    if (!(rr > 0.5 * *r && rr < 2 * *r)) continue;
    const int c = CountInliers(pts, x, y, rr, tol);
    if (c > best) best = c, bx = x, by = y, br = rr;
  }
  // Only a clearly better consensus (an eighth of the points more) replaces the start: on a
  // clean rim any three noisy points agree with fewer points than a good start does.
  if (best > start + static_cast<int>(n / 8)) *cx = bx, *cy = by, *r = br;
}

}  // namespace

CircleFitResult FitCircle(const std::vector<EdgePoint>& pts, const CircleFitParams& params) {
  CircleFitResult res;
  if (pts.size() < 3) return res;
  // Kasa: x^2 + y^2 + D x + E y + F = 0, least squares (centred for conditioning).
  double mx = 0, my = 0;
  for (const auto& p : pts) mx += p.x, my += p.y;
  mx /= static_cast<double>(pts.size());
  my /= static_cast<double>(pts.size());
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& p : pts) {
    const double x = p.x - mx, y = p.y - my;
    const Eigen::Vector3d row(x, y, 1.0);
    a += row * row.transpose();
    b -= row * (x * x + y * y);
  }
  const Eigen::Vector3d s = a.ldlt().solve(b);
  const double cx = -s[0] / 2, cy = -s[1] / 2;
  const double r2 = cx * cx + cy * cy - s[2];
  if (!(r2 > 0) || !std::isfinite(r2)) return res;
  double x = cx + mx, y = cy + my, r = std::sqrt(r2);
  ConsensusStart(pts, &x, &y, &r);
  return FitCircleFrom(pts, x, y, r, params);
}

CircleFitResult FitCircleFrom(const std::vector<EdgePoint>& pts, double cx, double cy, double r,
                              const CircleFitParams& params) {
  CircleFitResult res;
  if (pts.size() < 3 || !(r > 0)) return res;
  std::vector<double> resid(pts.size()), absr(pts.size()), dist(pts.size());
  double sigma = 0;
  for (int it = 0; it < params.iterations; ++it) {
    for (size_t i = 0; i < pts.size(); ++i) {
      dist[i] = std::hypot(pts[i].x - cx, pts[i].y - cy);  // once an iteration (hypot is slow)
      resid[i] = dist[i] - r;
      absr[i] = std::abs(resid[i]);
    }
    // Robust scale from the first iteration on, kept from shrinking below the floor.
    sigma = std::max(1.4826 * Median(absr), params.min_sigma_px);
    const double c = params.tukey_c * sigma;
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < pts.size(); ++i) {
      if (absr[i] >= c) continue;
      const double t = 1 - (resid[i] / c) * (resid[i] / c);
      const double w = t * t;
      const double dx = pts[i].x - cx, dy = pts[i].y - cy;
      const double d = std::max(dist[i], 1e-9);
      // residual = d - r; d/dcx = -dx/d, d/dcy = -dy/d, d/dr = -1
      const Eigen::Vector3d j(-dx / d, -dy / d, -1.0);
      jtj += w * j * j.transpose();
      jtr += w * j * resid[i];
    }
    if (params.radius_prior > 0 && params.radius_prior_weight > 0) {
      const Eigen::Vector3d j(0, 0, 1.0);
      jtj += params.radius_prior_weight * j * j.transpose();
      jtr += params.radius_prior_weight * j * (r - params.radius_prior);
    }
    if (std::abs(jtj.determinant()) < 1e-12) return res;
    const Eigen::Vector3d delta = -jtj.ldlt().solve(jtr);
    cx += delta[0];
    cy += delta[1];
    r += delta[2];
    if (!(r > 0) || !std::isfinite(cx) || !std::isfinite(cy)) return res;
    if (delta.norm() < 1e-4) break;
  }
  int inliers = 0;
  double ss = 0;
  const double c = params.tukey_c * sigma;
  for (const auto& p : pts) {
    const double e = std::hypot(p.x - cx, p.y - cy) - r;
    if (std::abs(e) < c) ++inliers, ss += e * e;
  }
  res.ok = inliers >= 3;
  res.cx = cx;
  res.cy = cy;
  res.r = r;
  res.inlier_fraction = static_cast<double>(inliers) / static_cast<double>(pts.size());
  res.rms = inliers > 0 ? std::sqrt(ss / inliers) : 0;
  return res;
}

}  // namespace bouncefit
