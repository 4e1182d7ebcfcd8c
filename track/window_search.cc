#include "track/window_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "track/ball_centre.h"
#include "track/ball_extent.h"
#include "track/ball_streak.h"
#include "track/inscribed_disc.h"

namespace bouncefit {

bool WindowSearch::FindNearPrediction(const Frame& frame, const Prediction& p, BallObservation* obs) {
  const double radius = ball_.radius();
  // A tight window first; then one wide enough for any reversal of the motion.
  const double tight = 1.6 * radius + config_.window_margin_px;
  if (Find(frame, p.at, tight, 0.5 * radius + config_.gate_px, obs)) return true;
  const double half = radius + std::max(radius, config_.window_margin_px) + 2 * p.motion_px;
  const double gate = radius + 2 * p.motion_px + config_.gate_px;
  if (Find(frame, p.at, half, gate, obs)) return true;
  // Fast enough to sweep half its radius over a frame: a streak too pale for the ball's colour.
  return radius > 0 && p.sweep_px > 0.5 * radius && FindStreak(frame, p.at, half, gate, p.sweep_px, obs);
}

bool WindowSearch::FindInEarlierFrame(const Frame& frame, cv::Point2f centre, double reach_px, double sweep_px,
                                      BallObservation* obs, double cut_radius_px) {
  looking_back_ = true;
  cut_radius_ = cut_radius_px;
  const double radius = ball_.radius();
  const double half = 1.6 * radius + config_.window_margin_px + reach_px;
  const double gate = 0.5 * radius + config_.gate_px + reach_px;
  bool ok = Find(frame, centre, half, gate, obs);
  if (!ok && sweep_px > 0.5 * radius) ok = FindStreak(frame, centre, half, gate, sweep_px, obs);
  looking_back_ = false;
  cut_radius_ = 0;
  planes_.rect = cv::Rect();  // an earlier frame's pixels: never taken for this one's
  return ok;
}

bool WindowSearch::CutByRoiBorder(const cv::Rect2f& box) const {
  return box.x <= roi_.x || box.y <= roi_.y || box.x + box.width >= roi_.br().x ||
         box.y + box.height >= roi_.br().y;
}

cv::Rect WindowSearch::WindowRect(cv::Point2f centre, double half) const {
  const int hw = static_cast<int>(std::ceil(half));
  return cv::Rect(static_cast<int>(std::lround(centre.x)) - hw, static_cast<int>(std::lround(centre.y)) - hw,
                  2 * hw + 1, 2 * hw + 1) & roi_;
}

bool WindowSearch::Find(const Frame& frame, cv::Point2f centre, double half, double gate, BallObservation* obs,
                        bool recentre) {
  const cv::Rect rect = WindowRect(centre, half);
  if (rect.width < 4 || rect.height < 4) return false;
  lock_.Planes(frame, rect, 1, config_.blur_sigma_px, &planes_);
  const double radius = ball_.radius();
  const double max_extent_px = ball_.expected().max_extent_px;
  const double followed_r = ball_.FollowedRadius();
  std::vector<Blob> blobs = SegmentBlobs(planes_, lock_.color(), ball_.SegmentParamsFor(followed_r, roi_), &mask_);
  const Blob* best = nullptr;
  double best_d = 0;
  bool best_moved = false;
  const bool inner_left = rect.x > roi_.x, inner_top = rect.y > roi_.y;
  const bool inner_right = rect.br().x < roi_.br().x, inner_bottom = rect.br().y < roi_.br().y;
  for (const Blob& b : blobs) {
    const double r = EquivalentRadius(b);
    const double d = std::hypot(b.centroid.x - centre.x, b.centroid.y - centre.y);
    if (d > gate + (b.touches_edge ? r : 0)) continue;
    // Running on beyond the window where the window is not the frame's (or ROI's) edge, and
    // larger than the ball: a patch of the ball's hue it passes in front of, not the ball.
    if (b.touches_edge && radius > 0 && b.pixels > 1.8 * std::numbers::pi * radius * radius + 20 &&
        ((inner_left && b.box.x <= rect.x) || (inner_top && b.box.y <= rect.y) ||
         (inner_right && b.box.x + b.box.width >= rect.br().x) ||
         (inner_bottom && b.box.y + b.box.height >= rect.br().y)))
      continue;
    if (radius > 0 && !b.touches_edge && !ball_.SizeMatches(r, radius)) continue;
    // Nothing followed yet (a colour or brightness given): a blob the frame's border cuts
    // cannot be told from the arm or the lamp it is (its size and shape are not all there).
    if (b.touches_edge && followed_r <= 0 && CutByRoiBorder(b.box)) continue;
    if (radius > 0 && !BoxCanBeBall(b.box.width, b.box.height, radius, max_extent_px)) continue;
    // Brightness mode: a blob that moves beats one that does not (the ghost of a ball held
    // still, left in the background model); a ball at rest is still followed.
    const bool moved = lock_.brightness() && lock_.MovedFraction(b.box) >= 0.15;
    if (!best || (moved && !best_moved) || (moved == best_moved && d < best_d))
      best = &b, best_d = d, best_moved = moved;
  }
  if (!best) return false;
  const Blob chosen = *best;
  // A close-up cut by the window where the window is not the frame's edge: a prediction off by
  // half its radius after an impact is tens of pixels, and the window missed part of it. Once
  // more, round it. (A smaller ball's cut blob is a smear running on, its centre found below:
  // a wider window took in the smear of a white ball on black cloth and moved its centres.)
  const bool window_cut = (inner_left && chosen.box.x <= rect.x) || (inner_top && chosen.box.y <= rect.y) ||
                          (inner_right && chosen.box.x + chosen.box.width >= rect.br().x) ||
                          (inner_bottom && chosen.box.y + chosen.box.height >= rect.br().y);
  if (window_cut && recentre && ball_.IsCloseUp(followed_r)) {
    const cv::Point2f at(chosen.box.x + 0.5f * chosen.box.width, chosen.box.y + 0.5f * chosen.box.height);
    const double grown = std::max(half, 0.5 * std::max(chosen.box.width, chosen.box.height) + 1.6 * followed_r + 8);
    if (Find(frame, at, grown, 1.6 * followed_r + 8, obs, false)) return true;
  }
  return Refine(frame, chosen, centre, obs);
}

bool WindowSearch::FindStreak(const Frame& frame, cv::Point2f centre, double half, double gate, double sweep_px,
                              BallObservation* obs) {
  const cv::Rect rect = WindowRect(centre, half);
  if (rect.width < 4 || rect.height < 4) return false;
  if (planes_.rect != rect || planes_.step != 1) lock_.Planes(frame, rect, 1, config_.blur_sigma_px, &planes_);
  const double radius = ball_.radius();
  const BallStreak s = FindBallStreak(planes_, lock_.color(), centre, gate, radius, 2 * radius + 1.5 * sweep_px + 4);
  if (!s.ok) return false;
  // A streak lies along the ball's path: as steep as the path was before (an impact turns it
  // back up but keeps its slope within e's change; a strip sliding along the floor does not).
  if (s.length_px > 1.3 * s.width_px && ball_.arc_speed_px_s() > 0) {
    const double slope_streak = std::atan2(std::abs(s.dir_y), std::abs(s.dir_x));
    const double slope_path = std::atan2(std::abs(ball_.arc_dir_y()), std::abs(ball_.arc_dir_x()));
    if (std::abs(slope_streak - slope_path) > config_.streak_max_turn_deg * std::numbers::pi / 180) return false;
  }
  shapeless_ = false;
  obs->found = true;
  obs->x = s.box.x, obs->y = s.box.y, obs->w = s.box.width, obs->h = s.box.height;
  obs->cx = static_cast<float>(s.cx);
  obs->cy = static_cast<float>(s.cy);
  obs->radius_px = static_cast<float>(radius);
  obs->pixel_count = s.pixels;
  obs->aspect_ratio = s.box.height > 0 ? s.box.width / s.box.height : 0;
  obs->score = 0.3f;
  return true;
}

bool WindowSearch::Refine(const Frame& frame, const Blob& blob, cv::Point2f expected, BallObservation* obs) {
  const double radius = ball_.radius();
  double r0 = EquivalentRadius(blob);
  if (blob.touches_edge && radius > 0) r0 = radius;
  const double cx = blob.centroid.x, cy = blob.centroid.y;
  auto rim_from = [&](double x, double y, double r) {
    PlanesRound(frame, x, y, r, &planes_);
    return FindBallCentre(planes_, lock_.color(), x, y, r, radius, config_.centre);
  };
  const cv::Rect mask_rect = planes_.rect;  // the window mask_ segmented
  if (RefineCut(frame, blob, obs)) return true;
  BallCentre bc = rim_from(cx, cy, r0);
  // Pieces joined across lines of another colour, their centroid far from the ball's centre
  // (the window cut the ball): rays from there cross the lines where they looked for the rim,
  // and the fit settles between the rim and the lines. Once more, from the circle found.
  if (blob.joined && bc.ok && std::hypot(bc.cx - cx, bc.cy - cy) > 0.1 * bc.r) {
    const BallCentre again = rim_from(bc.cx, bc.cy, bc.r);
    if (again.ok) bc = again;
  }
  bool from_expected = false;  // the rim found round another start: no colour adaptation
  // A blob the window cuts, its rim not found round its centroid: the ball run together with
  // something of its colour (its shadow on a floor of its hue). Where the ball was expected,
  // its rim may still be found; the merged blob's centroid is not the ball's centre.
  // Only for a slow ball (a fast one's prediction breaks at an impact), a blob the frame's
  // border does not cut (a ball half out of view has no rim to find there) and one as wide
  // and as tall as the ball at least (else the ball is not all in it: a sliver of it).
  if (!bc.ok && blob.touches_edge && radius > 0 && ball_.expected().motion_px < 0.5 * radius &&
      !CutByRoiBorder(blob.box) && std::min(blob.box.width, blob.box.height) >= 1.8 * radius &&
      std::hypot(expected.x - cx, expected.y - cy) > 0.25 * radius) {
    const BallCentre at_expected = rim_from(expected.x, expected.y, radius);
    if (at_expected.ok && !at_expected.cut && ball_.SizeMatches(at_expected.r, radius))
      bc = at_expected, from_expected = true;
  }
  // No round rim of the ball's size round the centroid: the ball run together with a patch of
  // its colour (the centroid lies between them; a close-up's rim, a hundred pixels out, then
  // lies beyond the rays' reach from it). The largest disc inside the blob sits in the ball.
  // A loose fit is no better: it settled between the ball's rim and the patch's edges.
  const auto loose = [&](const BallCentre& c) {
    return c.rms > std::max(config_.centre.loose_rms_px, config_.centre.loose_rms_radii * c.r);
  };
  // Its size not known yet (the first sighting), the disc's is taken. Close-ups only: a smaller
  // ball's rim is within the rays' reach of its centroid, and on football_door this start moved
  // the first fall's centres enough for the fitted ball to diverge in its export check.
  // A ball of known size that is no close-up never takes the disc: it is not looked for.
  const bool may_be_close_up = radius <= 0 || ball_.IsCloseUp(radius);
  if (!from_expected && may_be_close_up &&
      (!bc.ok || loose(bc) || (radius > 0 && !bc.cut && !ball_.SizeMatches(bc.r, radius)))) {
    const cv::Rect box = cv::Rect(blob.box) - mask_rect.tl();
    const InscribedDisc disc = LargestInscribedDisc(
        mask_, box, blob.box.x <= roi_.x, blob.box.y <= roi_.y, blob.box.x + blob.box.width >= roi_.br().x,
        blob.box.y + blob.box.height >= roi_.br().y);
    const double dx = mask_rect.x + disc.cx, dy = mask_rect.y + disc.cy;
    const double ref_r = radius > 0 ? radius : disc.r;
    if (disc.ok && ball_.IsCloseUp(ref_r) && disc.r > 0.5 * ref_r && std::hypot(dx - cx, dy - cy) > 0.1 * ref_r) {
      const BallCentre at_disc = rim_from(dx, dy, ref_r);
      const bool fits = at_disc.ok && (radius <= 0 || at_disc.cut || ball_.SizeMatches(at_disc.r, radius));
      if (fits && (!bc.ok || at_disc.rms < bc.rms)) bc = at_disc, from_expected = true;
    }
  }
  float score;
  bool shapeless = false;
  if (bc.ok) {
    if (radius > 0 && !bc.cut && !ball_.SizeMatches(bc.r, radius)) return false;
    score = static_cast<float>(bc.valid_rays * bc.inlier_fraction);
  } else if (blob.touches_edge) {
    // Ball cut by the frame or ROI border: the blob is all there is.
    bc.cx = cx, bc.cy = cy, bc.r = r0;
    score = 0.2f;
    shapeless = CutByRoiBorder(blob.box);
  } else if (radius > 0 && std::min(blob.box.width, blob.box.height) > 1.4 * radius &&
             std::min(blob.box.width, blob.box.height) < 2.6 * radius) {
    // Not round but ball-sized across: a ball smeared by motion blur (slow shutters). The
    // box centre is the centre of the smear, i.e. of the ball at mid-exposure.
    bc.cx = blob.box.x + 0.5 * (blob.box.width - 1);
    bc.cy = blob.box.y + 0.5 * (blob.box.height - 1);
    bc.r = radius;
    score = 0.3f;
  } else {
    return false;
  }
  shapeless_ = shapeless;
  Report(blob, bc.cx, bc.cy, bc.r, score, obs);
  // Not from a rim found only at the prediction: its surroundings are the patch it ran into.
  if (!looking_back_ && bc.ok && !bc.cut && !from_expected && bc.inlier_fraction > 0.8)
    lock_.Adapt(planes_, bc.cx, bc.cy, bc.r);
  return true;
}

void WindowSearch::PlanesRound(const Frame& frame, double x, double y, double r, YccPlanes* planes) const {
  const double reach = r + RimRayOvershootPx(r) + 3;
  const cv::Rect need = cv::Rect(static_cast<int>(std::floor(x - reach)) - 1,
                                 static_cast<int>(std::floor(y - reach)) - 1,
                                 static_cast<int>(2 * reach) + 4, static_cast<int>(2 * reach) + 4) & roi_;
  if ((need & planes->rect) != need) lock_.Planes(frame, need, 1, config_.blur_sigma_px, planes);
}

bool WindowSearch::RefineCut(const Frame& frame, const Blob& blob, BallObservation* obs) {
  // Its size is the nearest sighting's (a ball moving towards the camera or away changes size),
  // or the finder's for a ball just chosen.
  const double radius =
      cut_radius_ > 0 ? cut_radius_ : ball_.last_radius() > 0 ? ball_.last_radius() : ball_.FollowedRadius();
  if (radius <= 0 || !CutByRoiBorder(blob.box)) return false;
  const cv::Point2d start = CutBallStart(blob.box, roi_, radius);
  // Planes of its own, this frame's: a blob it does not place is refined as any other, on the
  // window's.
  cut_planes_.rect = cv::Rect();
  PlanesRound(frame, start.x, start.y, radius, &cut_planes_);
  const BallCentre bc =
      FindCutBallCentre(cut_planes_, lock_.color(), start.x, start.y, radius, blob.box, roi_, config_.centre);
  if (!bc.ok && !bc.too_little_rim) return false;
  // A sliver, no rim fitted to it: only its box says it is a cap of the ball.
  shapeless_ = !(bc.r > 0);
  // Too little of its rim in view to place its centre: the ball is there, its centre unknown.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Report(blob, bc.ok ? bc.cx : nan, bc.ok ? bc.cy : nan, bc.ok ? bc.r : radius,
         static_cast<float>(bc.ok ? bc.valid_rays * bc.inlier_fraction : 0.1), obs);
  return true;
}

void WindowSearch::Report(const Blob& blob, double cx, double cy, double r, float score, BallObservation* obs) const {
  obs->found = true;
  obs->x = blob.box.x;
  obs->y = blob.box.y;
  obs->w = blob.box.width;
  obs->h = blob.box.height;
  obs->cx = static_cast<float>(cx);
  obs->cy = static_cast<float>(cy);
  obs->radius_px = static_cast<float>(r);
  obs->pixel_count = blob.pixels;
  obs->aspect_ratio = blob.box.height > 0 ? blob.box.width / blob.box.height : 0;
  obs->score = std::clamp(score, 0.0f, 1.0f);
}

}  // namespace bouncefit
