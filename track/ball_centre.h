#pragma once
// Sub-pixel centre of a ball already found as a blob: rays from a rough centre; along each ray
// every sample is unmixed into ball coverage (ball colour of unknown shading over the ray's
// own background), and the rim is where coverage crosses 1/2 (unbiased under blur, motion
// blur and the dark shaded bottom); then a robust circle fit. Rays leaving the region (ball partly out of view or of the ROI) are
// dropped. A ball the region's border cuts is placed by the rim in view alone
// (FindCutBallCentre), when enough of it is in view.
#include <opencv2/core.hpp>

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
  // A ball the region's border cuts: the rim in view must span this much of the circle round
  // its centre for the centre to be placed (a short cap's centre moves with any error in the
  // radius held to), degrees; and this many rim points at least.
  double min_cut_arc_deg = 90;
  int min_cut_rim_points = 8;
};

struct BallCentre {
  bool ok = false;
  double cx = 0, cy = 0, r = 0;
  double valid_rays = 0;        // share of rays with a rim point
  double inlier_fraction = 0;   // share of rim points the circle accepts
  double rms = 0;               // pixels
  bool cut = false;             // some rays left the region
  // FindCutBallCentre: the span of the rim's points round the centre, degrees, and whether too
  // little of the ball is in view to place its centre (ok is false): a round rim of its size
  // too short, or a sliver too thin for rays (r is 0: no rim fitted) whose box is a cap of it.
  double arc_deg = 0;
  bool too_little_rim = false;
};

// How far past a ball of radius r (px) FindBallCentre's rays reach: its rim's blur ramp, which
// grows with the picture (a close-up on a 4K phone). The planes given it must cover this.
inline double RimRayOvershootPx(double r) { return std::clamp(0.6 * r, 4.0, std::max(10.0, 0.1 * r)); }

// `planes` must be full resolution (step 1) and cover the ball with a margin; (cx, cy, r) is
// the rough guess in frame pixels; radius_prior <= 0 means none.
BallCentre FindBallCentre(const YccPlanes& planes, const ColorModel& color, double cx, double cy,
                          double r, double radius_prior, const BallCentreParams& params);

// A ball the border of `planes` cuts (the planes end where the frame or the ROI does), of
// radius about `radius` px (its other sightings'), from a start (cx, cy) within a few pixels
// of its centre (CutBallStart): a circle fitted to the rim in view, the rays that leave the
// region dropped (the border's straight edge is no rim), its radius held to `radius` as far as
// a short arc leaves it open. Its part in view must be the blob's box (`box`: a ball cut by
// the border reaches across it; an arm reaching in does not end there). ok: the centre
// placed; too_little_rim: a round rim of the ball's size, too short to place it.
BallCentre FindCutBallCentre(const YccPlanes& planes, const ColorModel& color, double cx, double cy,
                             double radius, const cv::Rect2f& box, const cv::Rect& region,
                             const BallCentreParams& params);

// Where to start FindCutBallCentre for a blob whose box the region's border cuts: on each
// axis, the ball's radius in from the side of the box the border does not cut (the blob's far
// rim), or the box's middle where neither side is cut.
cv::Point2d CutBallStart(const cv::Rect2f& box, const cv::Rect& region, double radius);

}  // namespace bouncefit
