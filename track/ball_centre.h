#pragma once
// Sub-pixel centre of a ball already found as a blob: rays from a rough centre; along each ray
// every sample is unmixed into ball coverage (ball colour of unknown shading over the ray's
// own background), and the rim is where coverage crosses 1/2 (unbiased under blur, motion
// blur and the dark shaded bottom); then a robust circle fit. Rays leaving the region (ball partly out of view or of the ROI) are
// dropped.
#include <algorithm>
#include <vector>

#include "track/circle_fit.h"
#include "track/color_model.h"
#include "track/ycc_planes.h"

namespace bouncefit {

struct BallCentreParams {
  int rays = 64;
  double edge_min_contrast = 6;   // chroma the ball's inside needs on a ray (0-255 units)
  double radius_prior_weight = 2; // pull towards the tracked radius, in edge points
  double min_valid_rays = 0.35;   // share of rays that must give a rim point
  double max_rms_px = 1.5;        // worse inlier RMS means the blob is not a round ball
  // A fit looser than this (px, or radii when more) may have settled between the ball's rim
  // and the edges of what it ran into: the tracker tries a close-up again from inside its blob.
  double loose_rms_px = 1.0;
  double loose_rms_radii = 0.012;
};

struct BallCentre {
  bool ok = false;
  double cx = 0, cy = 0, r = 0;
  double valid_rays = 0;        // share of rays with a rim point
  double inlier_fraction = 0;   // share of rim points the circle accepts
  double rms = 0;               // pixels
  bool cut = false;             // some rays left the region
};

// How far past a ball of radius r (px) FindBallCentre's rays reach: its rim's blur ramp, which
// grows with the picture (a close-up on a 4K phone). The planes given it must cover this.
inline double RimRayOvershootPx(double r) { return std::clamp(0.6 * r, 4.0, std::max(10.0, 0.1 * r)); }

// `planes` must be full resolution (step 1) and cover the ball with a margin; (cx, cy, r) is
// the rough guess in frame pixels; radius_prior <= 0 means none.
BallCentre FindBallCentre(const YccPlanes& planes, const ColorModel& color, double cx, double cy,
                          double r, double radius_prior, const BallCentreParams& params);

}  // namespace bouncefit
