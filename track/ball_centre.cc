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
// *cut: the rays that left the region.
int CastRays(const Sampler& sm, const ColorModel& color, double cx, double cy, double r,
             const BallCentreParams& params, std::vector<EdgePoint>* pts, int* cut) {
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
      ++*cut;
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

// The fit as the ball's centre; ok when its rim is round enough to be a ball's.
void TakeFit(const CircleFitResult& fit, const BallCentreParams& params, BallCentre* out) {
  out->cx = fit.cx;
  out->cy = fit.cy;
  out->r = fit.r;
  out->rms = fit.rms;
  out->inlier_fraction = fit.inlier_fraction;
  out->ok = fit.inlier_fraction >= 0.5 && fit.rms <= std::max(params.max_rms_px, 0.04 * fit.r);
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
    int cut = 0;
    const int got = CastRays(sm, color, cx, cy, r, params, &pts, &cut);
    out.cut = cut > 0;
    out.valid_rays = static_cast<double>(got) / params.rays;
    if (out.valid_rays < params.min_valid_rays) return out;
    fit = FitCircleFrom(pts, cx, cy, r, fp);
    if (!fit.ok || fit.r < 0.5 * r || fit.r > 1.6 * r) return out;
    cx = fit.cx, cy = fit.cy, r = fit.r;
  }
  TakeFit(fit, params, &out);
  return out;
}

namespace {

// The span of the points' directions round (cx, cy), degrees: 360 less the widest gap between
// neighbouring directions.
double ArcSpanDeg(const std::vector<EdgePoint>& pts, double cx, double cy) {
  if (pts.size() < 2) return 0;
  std::vector<double> ang;
  ang.reserve(pts.size());
  for (const EdgePoint& p : pts) ang.push_back(std::atan2(p.y - cy, p.x - cx));
  std::sort(ang.begin(), ang.end());
  double gap = ang.front() + 2 * std::numbers::pi - ang.back();
  for (size_t i = 1; i < ang.size(); ++i) gap = std::max(gap, ang[i] - ang[i - 1]);
  return 360 - gap * 180 / std::numbers::pi;
}

// Whether the blob's box fits the part of the disc (cx, cy, r) inside `region`: no side more
// than `out_tol` px beyond it (smear and blur) nor more than `in_tol` px within it (a seam or a
// shaded part of the ball the segmentation missed). A ball the border cuts reaches across it,
// its cap's chord there as long as the box shows; an arm reaching in from the border does not
// end as a disc does.
bool BoxFitsInViewPart(double cx, double cy, double r, const cv::Rect2f& box, const cv::Rect& region,
                       double out_tol, double in_tol) {
  // Pixel indices: a pixel's outer edge is half a pixel beyond its centre.
  const double x0 = region.x - 0.5, x1 = region.br().x - 0.5, y0 = region.y - 0.5, y1 = region.br().y - 0.5;
  // The disc's extent along one axis within the region, from its widest chord there.
  const auto extent = [r](double c, double c_other, double lo_other, double hi_other, double lo, double hi,
                          double* a, double* b) {
    const double d = std::clamp(c_other, lo_other, hi_other) - c_other;
    if (std::abs(d) >= r) return false;
    const double half = std::sqrt(r * r - d * d);
    *a = std::max(c - half, lo), *b = std::min(c + half, hi);
    return *a < *b;
  };
  // The box side's offset outwards from the disc's.
  const auto fits = [&](double outwards) { return outwards <= out_tol && outwards >= -in_tol; };
  double ax, bx, ay, by;
  return extent(cx, cy, y0, y1, x0, x1, &ax, &bx) && extent(cy, cx, x0, x1, y0, y1, &ay, &by) &&
         fits(ax - (box.x - 0.5)) && fits(box.x + box.width - 0.5 - bx) && fits(ay - (box.y - 0.5)) &&
         fits(box.y + box.height - 0.5 - by);
}

}  // namespace

cv::Point2d CutBallStart(const cv::Rect2f& box, const cv::Rect& region, double radius) {
  // Box sides are pixel indices; the rim lies half a pixel beyond the outermost pixels.
  const auto on_axis = [radius](double lo, double hi, bool cut_lo, bool cut_hi) {
    if (cut_lo && !cut_hi) return hi - 0.5 - radius;
    if (cut_hi && !cut_lo) return lo - 0.5 + radius;
    return 0.5 * (lo + hi - 1);
  };
  return {on_axis(box.x, box.x + box.width, box.x <= region.x, box.x + box.width >= region.br().x),
          on_axis(box.y, box.y + box.height, box.y <= region.y, box.y + box.height >= region.br().y)};
}

BallCentre FindCutBallCentre(const YccPlanes& planes, const ColorModel& color, double cx, double cy,
                             double radius, const cv::Rect2f& box, const cv::Rect& region,
                             const BallCentreParams& params) {
  BallCentre out;
  out.cut = true;
  if (planes.step != 1 || !(radius > 0)) return out;
  const double tol = std::max(4.0, 0.15 * radius);
  const Sampler sm{planes};
  std::vector<EdgePoint> pts;
  pts.reserve(static_cast<size_t>(params.rays));
  CircleFitParams fp;
  fp.radius_prior = radius;
  fp.radius_prior_weight = params.radius_prior_weight;
  CircleFitResult fit;
  double r = radius;
  for (int pass = 0; pass < 2; ++pass) {
    int cut = 0;
    const int got = CastRays(sm, color, cx, cy, r, params, &pts, &cut);
    out.valid_rays = static_cast<double>(got) / params.rays;
    // A sliver: too few rays in view to find a rim on. A cap of the ball's size still.
    if (pass == 0 && params.rays - cut < params.min_cut_rim_points) {
      out.too_little_rim = BoxFitsInViewPart(cx, cy, radius, box, region, tol, tol);
      return out;
    }
    // Of the rays in view, as many must find the rim as of a whole ball's.
    if (got < params.min_cut_rim_points || got < params.min_valid_rays * (params.rays - cut)) return out;
    fit = FitCircleFrom(pts, cx, cy, r, fp);
    if (!fit.ok || fit.r < 0.5 * radius || fit.r > 1.6 * radius) return out;
    cx = fit.cx, cy = fit.cy, r = fit.r;
  }
  TakeFit(fit, params, &out);
  if (!out.ok || !BoxFitsInViewPart(fit.cx, fit.cy, fit.r, box, region, tol, fit.r)) {
    out.ok = false;
    return out;
  }
  out.arc_deg = ArcSpanDeg(pts, fit.cx, fit.cy);
  out.too_little_rim = out.arc_deg < params.min_cut_arc_deg;
  out.ok = !out.too_little_rim;
  return out;
}

}  // namespace bouncefit
