#pragma once
// The ball's colour as a point in luma-normalised chroma: n = (Cb-128, Cr-128) / Y. Shading and
// flicker scale Y and the chroma together, so n stays put on the ball's dark bottom and in
// changing light, while white, grey and black surfaces sit near n = 0.
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <string>

namespace bouncefit {

struct ColorModelParams {
  double tolerance_rel = 0.45;  // a pixel matches when |n - n0| <= tolerance_rel * |n0| ...
  double tolerance_min = 0.08;  // ... but never tighter than this (chroma per luma, unitless)
  double min_luma = 14;         // pixels darker than this (0-255) never match
  double luma_floor = 24;       // Y below this is taken as this when normalising (noise)
  // The same hue up to this many times as saturated also matches: a colour taken from the
  // ball's rim, its highlight or a motion-blurred frame is the body's hue mixed with grey,
  // never more saturated than the body (a dark green ball sampled in a smear reads light
  // green: the body lies 2x further out along the same direction). 1: a plain disc. Not for
  // pixels darker than twice luma_floor, whose normalised chroma is mostly noise (shadows);
  // only for a colour below washed_out (chroma/luma: a colour that saturated was not washed
  // out), and never beyond saturation_reach_max (stronger ones are shadows, saturated walls).
  double saturation_reach = 2.5;
  double washed_out = 0.5;
  double saturation_reach_max = 0.75;
  // A colour told to keep out (KeepOut: the ball's surroundings) stays beyond the tolerance
  // with a margin: the tolerance is at most this share of the distance to it (a pale orange
  // ball before a brown wall: 0.45 of the ball's chroma would take in the wall).
  double keep_out_share = 0.75;
};

class ColorModel {
 public:
  ColorModel() = default;
  ColorModel(double nu, double nv, ColorModelParams params);
  static ColorModel FromBgr(double b, double g, double r, ColorModelParams params);
  static ColorModel FromYuv(double y, double u, double v, ColorModelParams params);

  bool valid() const { return valid_; }
  double nu() const { return nu_; }
  double nv() const { return nv_; }
  double tolerance() const { return tol_; }
  // Unit vector of the chroma direction (for the linear edge signal u*dir_u + v*dir_v).
  double dir_u() const { return du_; }
  double dir_v() const { return dv_; }
  const ColorModelParams& params() const { return params_; }

  // Normalised chroma distance of one pixel (y, u, v as in YccPlanes) to the ball colour;
  // +inf for pixels darker than min_luma.
  // Distance to the segment from the colour out to `saturation_reach` times it.
  float Distance(float y, float u, float v) const { return Terms().Of(y, u, v); }
  bool Matches(float y, float u, float v) const { return Distance(y, u, v) <= ftol_; }
  // Distance() of n pixels at once, into `out`, and the match mask (255 where the distance is
  // within tolerance, else 0): the same arithmetic without branches, so that the compiler
  // computes several pixels per instruction (the window's segmentation is most of tracking).
  void DistanceRow(const float* y, const float* u, const float* v, int n, float* out,
                   uint8_t* match) const;

  // Keeps a colour (the ball's surroundings) from matching: shortens the saturation reach (an
  // orange ball before an ochre wall must not take in the wall's stronger orange) and caps
  // the tolerance (keep_out_share of the distance to it), wherever the colour adapts to.
  void KeepOut(double nu, double nv);

  // Moves the colour towards (nu, nv) by `rate` (0-1), staying within `max_drift` of `anchor`.
  void AdaptTowards(double nu, double nv, double rate, const ColorModel& anchor,
                    double max_drift);

  // A representative BGR colour (at luma 128) for messages.
  cv::Scalar ApproxBgr() const;
  std::string ToString() const;

 private:
  // The constants of Distance, copied out of the model: a loop over pixels that holds them in
  // locals keeps them apart from what it stores (the compiler then vectorizes it).
  struct DistanceTerms {
    float nu, nv, du, dv, reach, floor, dark;
    // Without branches (the same values as with them), so that a loop of it vectorizes.
    float Of(float y, float u, float v) const {
      const float inv = 1.0f / std::max(y, floor);
      float a = u * inv - nu, b = v * inv - nv;
      const float along = a * du + b * dv;
      const bool reaches = (along > 0) & (y >= 2 * floor);
      const float t = reaches ? std::min(along, reach) : 0.0f;
      a -= t * du, b -= t * dv;
      const float root = std::sqrt(a * a + b * b);
      return y < dark ? 1e9f : root;
    }
  };
  DistanceTerms Terms() const { return {fnu_, fnv_, fdu_, fdv_, freach_, luma_floor_, min_luma_}; }
  void Update();
  bool valid_ = false;
  double nu_ = 0, nv_ = 0, tol_ = 0, du_ = 0, dv_ = 0;
  double reach_end_ = 0;  // chroma/luma the hue's segment reaches out to (set with the colour)
  bool keep_out_ = false;
  double keep_out_nu_ = 0, keep_out_nv_ = 0;
  float fnu_ = 0, fnv_ = 0, ftol_ = 0, min_luma_ = 0, luma_floor_ = 1;
  float fdu_ = 0, fdv_ = 0, freach_ = 0;  // unit hue direction; how far along it still matches
  ColorModelParams params_;
};

}  // namespace bouncefit
