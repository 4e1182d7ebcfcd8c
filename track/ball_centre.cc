#include "track/ball_centre.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bouncefit {

namespace {

struct Sampler {
  const YccPlanes& p;
  // Whether frame point (x, y) is inside the region, its four neighbours with it.
  bool Inside(double x, double y) const {
    const double fx = x - p.rect.x, fy = y - p.rect.y;
    return !(fx < 0 || fy < 0 || fx > p.y.cols - 1.001 || fy > p.y.rows - 1.001);
  }
  // Y, U, V at frame point (x, y), bilinear, for a point Inside().
  void At(double x, double y, float out[3]) const {
    const double fx = x - p.rect.x, fy = y - p.rect.y;
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float ax = static_cast<float>(fx - ix), ay = static_cast<float>(fy - iy);
    const float w00 = (1 - ax) * (1 - ay), w01 = ax * (1 - ay), w10 = (1 - ax) * ay, w11 = ax * ay;
    const cv::Mat* planes[3] = {&p.y, &p.u, &p.v};
    for (int c = 0; c < 3; ++c) {
      const float* r0 = planes[c]->ptr<float>(iy) + ix;
      const float* r1 = planes[c]->ptr<float>(iy + 1) + ix;
      out[c] = w00 * r0[0] + w01 * r0[1] + w10 * r1[0] + w11 * r1[1];
    }
  }
};

// Rim points on rays from (cx, cy) for a ball of radius about r. Along each ray every sample
// is unmixed into ball coverage a: pixel - B = (a k) C - a B, with B the background (the
// ray's outer samples), C = (1, nu, nv) the ball colour per unit luma and k its unknown
// shading. a is linear in the blur, whatever the shading, so a = 0.5 is the rim.
// Samples are taken only as needed: the outer two (the background), the innermost (is it the
// ball?), then inwards from the outside to the first crossing, most rays' first third unread.
int CastRays(const Sampler& sm, const ColorModel& color, double cx, double cy, double r,
             const BallCentreParams& params, std::vector<EdgePoint>* pts, bool* cut) {
  pts->clear();
  // From inside the rim (past any motion-blur ramp) to the background; coarser steps on big
  // balls (coverage is smooth across the rim, the crossing is interpolated).
  const double kStep = std::clamp(r / 24, 0.5, 1.0);
  // The rim's blur ramp grows with the picture (a close-up on a 4K phone): so does the span.
  const double r_in = std::max(0.3 * r, r - std::clamp(0.4 * r, 2.5, std::max(9.0, 0.1 * r)));
  const double r_hi = r + RimRayOvershootPx(r);
  const int n = static_cast<int>(std::ceil((r_hi - r_in) / kStep)) + 1;
  const double c0 = 1, c1 = color.nu(), c2 = color.nv();
  const double cc = c0 * c0 + c1 * c1 + c2 * c2;
  for (int k = 0; k < params.rays; ++k) {
    const double ang = 2 * std::numbers::pi * (k + 0.5) / params.rays;
    const double c = std::cos(ang), sn = std::sin(ang);
    auto sample = [&](int i, float out[3]) {
      const double rr = r_in + i * kStep;
      sm.At(cx + rr * c, cy + rr * sn, out);
    };
    // Each coordinate moves monotonically along the ray (in floating point too): the ray is
    // inside the region when both its ends are.
    const double rr_last = r_in + (n - 1) * kStep;
    if (!sm.Inside(cx + r_in * c, cy + r_in * sn) || !sm.Inside(cx + rr_last * c, cy + rr_last * sn)) {
      *cut = true;
      continue;
    }
    float o1[3], o2[3], p[3];
    sample(n - 1, o1);
    sample(n - 2, o2);
    const double b0 = 0.5 * (o1[0] + o2[0]), b1 = 0.5 * (o1[1] + o2[1]), b2 = 0.5 * (o1[2] + o2[2]);
    const double bb = b0 * b0 + b1 * b1 + b2 * b2, cb = c0 * b0 + c1 * b1 + c2 * b2;
    const double det = cc * bb - cb * cb;
    if (det < 1e-6 * cc * bb) continue;
    // Least squares for (x1, x2) = (a k, a): [cc, -cb; -cb, bb] x = [C.d; -B.d], d = p - B.
    auto coverage = [&](const float* q, double* x1) {
      const double d0 = q[0] - b0, d1 = q[1] - b1, d2 = q[2] - b2;
      const double cd = c0 * d0 + c1 * d1 + c2 * d2, bd = -(b0 * d0 + b1 * d1 + b2 * d2);
      if (x1) *x1 = (bb * cd + cb * bd) / det;
      return (cb * cd + cc * bd) / det;
    };
    double k_in = 0;
    sample(0, p);
    const double a_in = coverage(p, &k_in);
    // The inside must be the ball: covered, and with enough chroma to tell it apart.
    if (a_in < 0.6 || k_in * std::hypot(c1, c2) < params.edge_min_contrast) continue;
    double a1 = coverage(o1, nullptr);
    for (int i = n - 2; i >= 0; --i) {
      double a0 = a_in;
      if (i == n - 2)
        a0 = coverage(o2, nullptr);
      else if (i > 0)
        sample(i, p), a0 = coverage(p, nullptr);
      if (a0 >= 0.5 && a1 < 0.5) {
        const double rr = r_in + (i + (a0 - 0.5) / (a0 - a1)) * kStep;
        pts->push_back({cx + rr * c, cy + rr * sn});
        break;
      }
      a1 = a0;
    }
  }
  return static_cast<int>(pts->size());
}

}  // namespace

BallCentre FindBallCentre(const YccPlanes& planes, const ColorModel& color, double cx, double cy,
                          double r, double radius_prior, const BallCentreParams& params) {
  BallCentre out;
  if (planes.step != 1 || !(r > 0)) return out;
  const Sampler sm{planes};
  std::vector<EdgePoint> pts;
  pts.reserve(static_cast<size_t>(params.rays));
  CircleFitParams fp;
  fp.radius_prior = radius_prior;
  fp.radius_prior_weight = radius_prior > 0 ? params.radius_prior_weight : 0;
  CircleFitResult fit;
  for (int pass = 0; pass < 2; ++pass) {
    out.cut = false;
    const int got = CastRays(sm, color, cx, cy, r, params, &pts, &out.cut);
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
  out.ok = fit.inlier_fraction >= 0.5 && fit.rms <= std::max(params.max_rms_px, 0.04 * fit.r);
  return out;
}

}  // namespace bouncefit
