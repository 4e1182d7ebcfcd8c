#include "track/ball_centre.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bouncefit {

namespace {

struct Sampler {
  const YccPlanes& p;
  float du, dv;
  // Linear chroma signal along the ball's colour direction at frame point (x, y); false when
  // the point is not inside the region.
  bool At(double x, double y, float* s) const {
    const double fx = x - p.rect.x, fy = y - p.rect.y;
    if (fx < 0 || fy < 0 || fx > p.y.cols - 1.001 || fy > p.y.rows - 1.001) return false;
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float ax = static_cast<float>(fx - ix), ay = static_cast<float>(fy - iy);
    const float* u0 = p.u.ptr<float>(iy) + ix;
    const float* u1 = p.u.ptr<float>(iy + 1) + ix;
    const float* v0 = p.v.ptr<float>(iy) + ix;
    const float* v1 = p.v.ptr<float>(iy + 1) + ix;
    const float s00 = u0[0] * du + v0[0] * dv, s01 = u0[1] * du + v0[1] * dv;
    const float s10 = u1[0] * du + v1[0] * dv, s11 = u1[1] * du + v1[1] * dv;
    *s = (1 - ay) * ((1 - ax) * s00 + ax * s01) + ay * ((1 - ax) * s10 + ax * s11);
    return true;
  }
};

// Rim points on rays from (cx, cy) for a ball of radius about r.
int CastRays(const Sampler& sm, double cx, double cy, double r, const BallCentreParams& params,
             std::vector<EdgePoint>* pts, bool* cut) {
  pts->clear();
  constexpr double kStep = 0.5;
  const double r_in = std::max(0.3 * r, r - std::max(2.5, 0.4 * r));
  const double r_hi = r + std::max(4.0, 0.6 * r);
  const int n = static_cast<int>(std::ceil((r_hi - r_in) / kStep)) + 1;
  std::vector<float> s(static_cast<size_t>(n));
  for (int k = 0; k < params.rays; ++k) {
    const double a = 2 * std::numbers::pi * (k + 0.5) / params.rays;
    const double c = std::cos(a), sn = std::sin(a);
    bool inside = true;
    for (int i = 0; i < n && inside; ++i) {
      const double rr = r_in + i * kStep;
      inside = sm.At(cx + rr * c, cy + rr * sn, &s[static_cast<size_t>(i)]);
    }
    if (!inside) {
      *cut = true;
      continue;
    }
    const float s_in = s[0];
    const float s_out = 0.5f * (s[static_cast<size_t>(n - 1)] + s[static_cast<size_t>(n - 2)]);
    if (s_in - s_out < params.edge_min_contrast) continue;
    const float level = 0.5f * (s_in + s_out);
    for (int i = n - 2; i >= 0; --i) {
      const float a0 = s[static_cast<size_t>(i)], a1 = s[static_cast<size_t>(i + 1)];
      if (a0 >= level && a1 < level) {
        const double rr = r_in + (i + (a0 - level) / (a0 - a1)) * kStep;
        pts->push_back({cx + rr * c, cy + rr * sn});
        break;
      }
    }
  }
  return static_cast<int>(pts->size());
}

}  // namespace

BallCentre FindBallCentre(const YccPlanes& planes, const ColorModel& color, double cx, double cy,
                          double r, double radius_prior, const BallCentreParams& params) {
  BallCentre out;
  if (planes.step != 1 || !(r > 0)) return out;
  const Sampler sm{planes, static_cast<float>(color.dir_u()), static_cast<float>(color.dir_v())};
  std::vector<EdgePoint> pts;
  pts.reserve(static_cast<size_t>(params.rays));
  CircleFitParams fp;
  fp.radius_prior = radius_prior;
  fp.radius_prior_weight = radius_prior > 0 ? params.radius_prior_weight : 0;
  CircleFitResult fit;
  for (int pass = 0; pass < 2; ++pass) {
    out.cut = false;
    const int got = CastRays(sm, cx, cy, r, params, &pts, &out.cut);
    out.valid_rays = static_cast<double>(got) / params.rays;
    if (out.valid_rays < params.min_valid_rays) return out;
    fit = FitCircleFrom(pts, cx, cy, r, fp);
    if (!fit.ok || fit.r < 0.5 * r || fit.r > 1.6 * r) return out;
    cx = fit.cx, cy = fit.cy, r = fit.r;
  }
  out.cx = fit.cx;
  out.cy = fit.cy;
  out.r = fit.r;
  out.rms = fit.rms;
  out.inlier_fraction = fit.inlier_fraction;
  out.ok = fit.inlier_fraction >= 0.5 && fit.rms <= params.max_rms_px;
  return out;
}

}  // namespace bouncefit
