#include "track/tracker.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "track/ball_extent.h"
#include "track/inscribed_disc.h"

namespace bouncefit {

bool TrackerConfig::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (has_pick + has_color + has_chroma > 1) return fail("give either a pick point or a colour, not both");
  if (has_pick && (pick_x < 0 || pick_y < 0)) return fail("pick point must not be negative");
  for (double c : color_bgr)
    if (c < 0 || c > 255) return fail("colour components must be 0-255");
  if (roi_x < 0 || roi_y < 0 || roi_w < 0 || roi_h < 0) return fail("ROI must not be negative");
  if (blur_sigma_px < 0 || blur_sigma_px > 5) return fail("blur sigma must be 0-5 px");
  if (color.tolerance_rel <= 0 || color.tolerance_rel > 2) return fail("colour tolerance must be in (0, 2]");
  if (!(color.saturation_reach >= 1)) return fail("colour saturation reach must be >= 1");
  if (segment.min_box_px < 1 || segment.max_box_px <= segment.min_box_px)
    return fail("box limits must satisfy 1 <= min < max");
  if (centre.rays < 8 || centre.rays > 1024) return fail("rays must be 8-1024");
  if (adapt_rate < 0 || adapt_rate > 1) return fail("adapt rate must be 0-1");
  if (finder.max_work_pixels < 1000) return fail("finder work size must be >= 1000 pixels");
  if (still_review_work_pixels != 0 && still_review_work_pixels < 1000)
    return fail("still-review work size must be 0 or >= 1000 pixels");
  if (finder.lag_s < 0) return fail("finder lag must be >= 0 s");
  if (!(auto_review_s >= 0)) return fail("review interval must be >= 0 s");
  if (luma.polarity < -1 || luma.polarity > 1) return fail("luma polarity must be -1, 0 or +1");
  if (luma.min_contrast_luma <= 0 || luma.clamp_luma <= luma.min_contrast_luma)
    return fail("luma contrast limits must satisfy 0 < min < clamp");
  if (luma.background_rate <= 0 || luma.background_rate > 1) return fail("background rate must be in (0, 1]");
  if (!(luma_contrast_share > 0) || !(luma_min_scale > 0 && luma_min_scale <= 1))
    return fail("luma contrast share must be > 0 and its least scale in (0, 1]");
  return true;
}

namespace {
BallFinderParams StillReviewParams(const TrackerConfig& c) {
  BallFinderParams p = c.finder;
  if (c.still_review_work_pixels > 0) p.max_work_pixels = std::min(p.max_work_pixels, c.still_review_work_pixels);
  return p;
}
}  // namespace

Tracker::Tracker(TrackerConfig config)
    : config_(std::move(config)), predictor_(config_.motion), camera_(config_.camera), finder_(config_.finder, config_.color),
      still_finder_(StillReviewParams(config_), config_.color), arc_(config_.arc) {
  std::string error;
  if (!config_.IsValid(&error)) throw std::invalid_argument("tracker: " + error);
  how_ = "no colour chosen yet";
}

BallObservation Tracker::Track(const Frame& frame) {
  BallObservation obs;
  obs.utime = frame.utime;
  obs.frame = frame.index;
  if (frame.image.empty()) throw std::invalid_argument("tracker: empty frame");
  CheckFrameFormat(frame);
  if (frame.image.size() != size_) {
    size_ = frame.image.size();
    const cv::Rect full(0, 0, size_.width, size_.height);
    roi_ = (config_.roi_w > 0 && config_.roi_h > 0)
               ? cv::Rect(config_.roi_x, config_.roi_y, config_.roi_w, config_.roi_h) & full
               : full;
    const std::string frame_size = std::to_string(size_.width) + "x" + std::to_string(size_.height);
    if (size_.width < 8 || size_.height < 8)
      throw std::invalid_argument("tracker: a " + frame_size +
                                  " px picture is too small to find a ball in (8x8 at least)");
    if (roi_.width < 8 || roi_.height < 8)
      throw std::invalid_argument("tracker: ROI lies outside the " + frame_size + " frame");
  }
  ++frames_;
  // A brightness lock reads the frame's luma first: the camera's profiles reuse it when the
  // source gave none of its own (a BGR frame's; a YUYV frame's is rescaled there and taken
  // raw here).
  const bool had_luma = luma_ != nullptr;
  if (had_luma) SetLumaFrame(frame);
  if (config_.follow_camera) {
    // The decoder's own luma where the source kept it (the Y the BGR picture was made from:
    // no conversion back), else a brightness lock's.
    const bool own = !frame.luma.empty();
    const bool shared = luma_ && frame.format != PixelFormat::kYuyv;
    camera_.Update(frame, WhereBallMayBe(static_cast<double>(frame.utime) * 1e-6),
                   own ? &frame.luma : shared ? &luma_->luma() : nullptr,
                   own && frame.luma_limited_range ? 255.0 / 219.0 : 1.0, own ? frame.luma_turn_cw_deg : 0);
    obs.camera_dx = static_cast<float>(camera_.dx());
    obs.camera_dy = static_cast<float>(camera_.dy());
  }
  // The prediction and the arc check follow the ball in the scene: a held camera's jitter
  // is not the ball's motion.
  cam_x_ = obs.camera_dx, cam_y_ = obs.camera_dy;
  if (!color_.valid() && !ChooseColor(frame)) {
    ++lost_;
    return obs;
  }
  // Brightness chosen just now (given, or the automatic choice's): a lock that held at the
  // top has its colour, so ChooseColor did not run and could not replace it.
  if (luma_ && !had_luma) SetLumaFrame(frame);
  if (luma_ && forget_ball_) {
    // Chosen just now: the ball is in the first background; take it out.
    luma_->ForgetBall(chosen_.x, chosen_.y, chosen_.r);
    forget_ball_ = false;
  }
  if (lookalikes_pending_) RememberLookalikes(frame), lookalikes_pending_ = false;
  const double t = static_cast<double>(frame.utime) * 1e-6;
  bool ok = false;
  double px, py, speed;
  max_extent_px_ = 0;
  double sweep_px = 0;  // how far the ball may move over a frame period, px (0: unknown)
  expected_motion_px_ = 1e9;  // no prediction: nothing expected
  if (last_frame_t_ >= 0 && t > last_frame_t_) frame_dt_s_ = t - last_frame_t_;
  last_frame_t_ = t;
  if (lost_ <= 2 && PredictInFrame(t, &px, &py, &speed)) {
    // An arc just begun (an impact, a kick) has no speed of its own yet: the ball leaves it
    // at most as fast as it came.
    double ax = 0, ay = 0;
    if (predictor_.samples() >= 3 && PredictInFrame(t + 1e-3, &ax, &ay) && speed > 0)
      arc_speed_px_s_ = speed, arc_dir_x_ = (ax - px) / (1e-3 * speed), arc_dir_y_ = (ay - py) / (1e-3 * speed);
    else
      speed = std::max(speed, arc_speed_px_s_);
    const double dt = std::clamp(t - last_t_, 1e-3, 0.1);
    const double motion = speed * dt;
    const double frame_dt = frame_dt_s_ > 0 ? frame_dt_s_ : dt;
    max_extent_px_ = radius_ > 0 ? MaxBallExtentPx(radius_, speed, frame_dt) : 0;
    const cv::Point2f pred(static_cast<float>(px), static_cast<float>(py));
    expected_motion_px_ = motion;
    sweep_px = speed * frame_dt;
    // In flight the parabola predicts to a pixel: a tight window first. A bounce or a kick
    // breaks the prediction: then a window wide enough for any reversal of the motion.
    const double tight = 1.6 * radius_ + config_.window_margin_px;
    ok = TryWindow(frame, pred, tight, 0.5 * radius_ + config_.gate_px, &obs);
    if (!ok) {
      const double half = radius_ + std::max(radius_, config_.window_margin_px) + 2 * motion;
      const double gate = radius_ + 2 * motion + config_.gate_px;
      ok = TryWindow(frame, pred, half, gate, &obs);
      // Fast enough to sweep half its radius over a frame: a streak too pale for the ball's colour.
      if (!ok && radius_ > 0 && sweep_px > 0.5 * radius_) ok = TryStreak(frame, pred, half, gate, sweep_px, &obs);
    }
  }
  if (!ok && has_seed_) {
    // Just chosen automatically: look where the finder saw it before searching everywhere.
    has_seed_ = false;
    const cv::Point2f seed(static_cast<float>(chosen_.x), static_cast<float>(chosen_.y));
    ok = TryWindow(frame, seed, 3 * chosen_.r + 12, 2 * chosen_.r + 10, &obs);
  }
  if (!ok) ok = Acquire(frame, &obs);
  if (ok) {
    predictor_.Add(t, obs.cx - cam_x_, obs.cy - cam_y_);
    radius_ = radius_ > 0 ? 0.8 * radius_ + 0.2 * obs.radius_px : obs.radius_px;
    lost_ = 0;
    last_t_ = t;
    last_cx_ = obs.cx, last_cy_ = obs.cy;
    ++found_;
  } else {
    ++lost_;
    if (lost_ > config_.lost_frames_keep) predictor_.Reset(), arc_speed_px_s_ = 0;
  }
  if (luma_) {
    // The background is kept from absorbing the ball only while it moves or has just come to
    // rest: a lock on something static (a patch of wall that brightened) fades out.
    if (ok && std::hypot(obs.cx - still_x_, obs.cy - still_y_) > 0.5 * radius_ + 1)
      still_x_ = obs.cx, still_y_ = obs.cy, still_frames_ = 0;
    else
      ++still_frames_;
    const bool keep = still_frames_ <= config_.luma_still_frames;
    luma_->UpdateBackground(last_cx_, last_cy_, keep ? radius_ : 0);
  }
  tentative_ = ok && auto_ && shapeless_;
  if (auto_) ReviewAutoLock(frame, obs);
  return obs;
}

bool Tracker::ChooseColor(const Frame& frame) {
  const ColorModelParams& cp = config_.color;
  if (config_.luma_mode) {
    StartLumaMode(config_.luma.polarity);
    how_ = (config_.color_name.empty() ? std::string("brightness") : config_.color_name) + how_;
  } else if (config_.has_color) {
    color_ = ColorModel::FromBgr(config_.color_bgr[0], config_.color_bgr[1],
                                 config_.color_bgr[2], cp);
    how_ = "colour " + (config_.color_name.empty() ? std::string("given") : config_.color_name);
  } else if (config_.has_chroma) {
    color_ = ColorModel(config_.chroma_nu, config_.chroma_nv, cp);
    how_ = config_.color_name.empty() ? std::string("colour given") : config_.color_name;
  } else if (config_.has_pick) {
    const PickedColor picked = PickColor(frame, config_.pick_x, config_.pick_y, cp, config_.blur_sigma_px);
    color_ = picked.color;
    how_ = fmt::format("picked pixel {:.0f},{:.0f}", config_.pick_x, config_.pick_y);
    // Nearly grey: follow its brightness instead, brighter or darker than its surroundings.
    if (picked.grey) {
      StartLumaMode(picked.polarity);
      how_ = fmt::format("picked pixel {:.0f},{:.0f}, nearly grey:{}", config_.pick_x, config_.pick_y, how_);
    }
  } else {
    return AutoChoose(frame);
  }
  anchor_ = color_;
  if (!luma_) how_ += ": " + color_.ToString();
  return true;
}

bool Tracker::SizeMatches(double r, double ref_r) const {
  return std::abs(r - ref_r) <= config_.radius_change * ref_r + 1.5;
}

bool Tracker::CutByRoiBorder(const cv::Rect2f& box) const {
  return box.x <= roi_.x || box.y <= roi_.y || box.x + box.width >= roi_.br().x ||
         box.y + box.height >= roi_.br().y;
}

double Tracker::FollowedRadius() const {
  if (radius_ > 0) return radius_;
  return color_.valid() && auto_ ? chosen_.r : 0;  // just chosen: the finder's size
}

bool Tracker::IsCloseUp(double radius_px) const {
  // 2.6 radii: a ball's box once smeared by its motion.
  return 2.6 * radius_px > config_.segment.max_box_px;
}

SegmenterParams Tracker::SegmentParamsFor(double radius_px) const {
  // A close-up ball outgrows the configured box limit: the limit grows with the ball followed.
  SegmenterParams p = config_.segment;
  if (IsCloseUp(radius_px))
    p.max_box_px = std::max(p.max_box_px, std::max(max_extent_px_, MaxBallExtentPx(radius_px, 0, 0)));
  return p;
}

cv::Rect Tracker::WindowRect(cv::Point2f centre, double half) const {
  const int hw = static_cast<int>(std::ceil(half));
  return cv::Rect(static_cast<int>(std::lround(centre.x)) - hw, static_cast<int>(std::lround(centre.y)) - hw,
                  2 * hw + 1, 2 * hw + 1) & roi_;
}

bool Tracker::TryWindow(const Frame& frame, cv::Point2f centre, double half, double gate,
                        BallObservation* obs, bool recentre) {
  const cv::Rect rect = WindowRect(centre, half);
  if (rect.width < 4 || rect.height < 4) return false;
  Planes(frame, rect, 1, config_.blur_sigma_px, &planes_);
  const double followed_r = FollowedRadius();
  std::vector<Blob> blobs = SegmentBlobs(planes_, color_, SegmentParamsFor(followed_r), &mask_);
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
    if (b.touches_edge && radius_ > 0 && b.pixels > 1.8 * std::numbers::pi * radius_ * radius_ + 20 &&
        ((inner_left && b.box.x <= rect.x) || (inner_top && b.box.y <= rect.y) ||
         (inner_right && b.box.x + b.box.width >= rect.br().x) ||
         (inner_bottom && b.box.y + b.box.height >= rect.br().y)))
      continue;
    if (radius_ > 0 && !b.touches_edge &&
        !SizeMatches(r, radius_))
      continue;
    // Nothing followed yet (a colour or brightness given): a blob the frame's border cuts
    // cannot be told from the arm or the lamp it is (its size and shape are not all there).
    if (b.touches_edge && followed_r <= 0 && CutByRoiBorder(b.box)) continue;
    if (radius_ > 0 && !BoxCanBeBall(b.box.width, b.box.height, radius_, max_extent_px_)) continue;
    // Brightness mode: a blob that moves beats one that does not (the ghost of a ball held
    // still, left in the background model); a ball at rest is still followed.
    const bool moved = luma_ && luma_->MovedFraction(b.box) >= 0.15;
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
  if (window_cut && recentre && IsCloseUp(followed_r)) {
    const cv::Point2f at(chosen.box.x + 0.5f * chosen.box.width, chosen.box.y + 0.5f * chosen.box.height);
    const double grown = std::max(half, 0.5 * std::max(chosen.box.width, chosen.box.height) + 1.6 * followed_r + 8);
    if (TryWindow(frame, at, grown, 1.6 * followed_r + 8, obs, false)) return true;
  }
  return Refine(frame, chosen, centre, obs);
}

bool Tracker::TryStreak(const Frame& frame, cv::Point2f centre, double half, double gate, double sweep_px,
                        BallObservation* obs) {
  const cv::Rect rect = WindowRect(centre, half);
  if (rect.width < 4 || rect.height < 4) return false;
  if (planes_.rect != rect || planes_.step != 1) Planes(frame, rect, 1, config_.blur_sigma_px, &planes_);
  const BallStreak s = FindBallStreak(planes_, color_, centre, gate, radius_, 2 * radius_ + 1.5 * sweep_px + 4);
  if (!s.ok) return false;
  // A streak lies along the ball's path: as steep as the path was before (an impact turns it
  // back up but keeps its slope within e's change; a strip sliding along the floor does not).
  if (s.length_px > 1.3 * s.width_px && arc_speed_px_s_ > 0) {
    const double slope_streak = std::atan2(std::abs(s.dir_y), std::abs(s.dir_x));
    const double slope_path = std::atan2(std::abs(arc_dir_y_), std::abs(arc_dir_x_));
    if (std::abs(slope_streak - slope_path) > config_.streak_max_turn_deg * std::numbers::pi / 180) return false;
  }
  shapeless_ = false;
  obs->found = true;
  obs->x = s.box.x, obs->y = s.box.y, obs->w = s.box.width, obs->h = s.box.height;
  obs->cx = static_cast<float>(s.cx);
  obs->cy = static_cast<float>(s.cy);
  obs->radius_px = static_cast<float>(radius_);
  obs->pixel_count = s.pixels;
  obs->aspect_ratio = s.box.height > 0 ? s.box.width / s.box.height : 0;
  obs->score = 0.3f;
  return true;
}

bool Tracker::Acquire(const Frame& frame, BallObservation* obs) {
  ++acquisitions_;
  Planes(frame, roi_, 2, 0.5 * config_.blur_sigma_px, &wide_);
  cv::Mat wide_mask;
  std::vector<Blob> blobs = SegmentBlobs(wide_, color_, SegmentParamsFor(FollowedRadius()), &wide_mask);
  const double tol = color_.tolerance();
  double px = 0, py = 0;
  const bool have_pred = lost_ <= config_.lost_frames_keep && PredictInFrame(
      static_cast<double>(frame.utime) * 1e-6, &px, &py);
  std::vector<std::pair<double, size_t>> order;
  for (size_t k = 0; k < blobs.size(); ++k) {
    const Blob& b = blobs[k];
    const double r = EquivalentRadius(b);
    // Brightness mode acquires only what moves: not the ghost a ball held still leaves in
    // the background model, nor a patch of wall the light changed.
    if (luma_ && luma_->MovedFraction(b.box) < 0.15) continue;
    // Colour first (a similar-hue object is a worse match), then shape, size, prediction.
    double score = 3 * b.mean_distance / tol + std::abs(b.fill - 0.785);
    if (radius_ > 0) score += std::abs(r - radius_) / radius_;
    if (have_pred)
      score += std::hypot(b.centroid.x - px, b.centroid.y - py) / (radius_ + 20);
    bool lookalike = false;
    for (const Remembered& m : distractors_)
      if (std::hypot(b.centroid.x - m.p.x, b.centroid.y - m.p.y) < std::max(3.0, 0.3 * m.r)) {
        score += 3;
        // Of the ball's hue, where it already was when the ball was chosen, and unmoved:
        // never the ball (which moved to be chosen), unless the prediction brings it there.
        lookalike = lookalike || (m.at_choice && std::abs(EquivalentRadius(b) - m.r) < 0.3 * m.r + 1.5);
      }
    if (lookalike && (!have_pred || std::hypot(b.centroid.x - px, b.centroid.y - py) > 2 * radius_ + 4)) continue;
    bool moved = !last_candidates_.empty();
    for (const Blob& o : last_candidates_)
      if (std::hypot(b.centroid.x - o.centroid.x, b.centroid.y - o.centroid.y) < 1.5) moved = false;
    if (moved) score -= 0.5;
    order.emplace_back(score, k);
  }
  std::sort(order.begin(), order.end());
  last_candidates_ = blobs;
  // Try the best few: the half-resolution blob must hold up at full resolution.
  for (size_t i = 0; i < order.size() && i < 3; ++i) {
    const Blob& b = blobs[order[i].second];
    const double r = EquivalentRadius(b);
    // A ball the frame's border cuts shows a cap whose chord along the border is as long as
    // its radius once the cap is an eighth of a radius deep; a shorter sliver there (a glint at
    // the top of the frame while the ball falls at its bottom) is not taken for the ball.
    if (radius_ > 0 && CutByRoiBorder(b.box) && std::max(b.box.width, b.box.height) < radius_) continue;
    if (TryWindow(frame, b.centroid, 1.6 * r + 10, r + 4, obs)) {
      for (const auto& [s, k] : order) {
        const Blob& o = blobs[k];
        if (std::hypot(o.centroid.x - obs->cx, o.centroid.y - obs->cy) < 2 * obs->radius_px) continue;
        bool known = false;
        for (const Remembered& m : distractors_)
          if (std::hypot(o.centroid.x - m.p.x, o.centroid.y - m.p.y) < 3) known = true;
        if (!known && distractors_.size() < 16)
          distractors_.push_back({o.centroid, static_cast<float>(EquivalentRadius(o))});
      }
      return true;
    }
  }
  return false;
}

bool Tracker::Refine(const Frame& frame, const Blob& blob, cv::Point2f expected, BallObservation* obs) {
  double r0 = EquivalentRadius(blob);
  if (blob.touches_edge && radius_ > 0) r0 = radius_;
  const double cx = blob.centroid.x, cy = blob.centroid.y;
  auto rim_from = [&](double x, double y, double r) {
    const double reach = r + RimRayOvershootPx(r) + 3;
    const cv::Rect need = cv::Rect(static_cast<int>(std::floor(x - reach)) - 1,
                                   static_cast<int>(std::floor(y - reach)) - 1,
                                   static_cast<int>(2 * reach) + 4, static_cast<int>(2 * reach) + 4) & roi_;
    if ((need & planes_.rect) != need) Planes(frame, need, 1, config_.blur_sigma_px, &planes_);
    return FindBallCentre(planes_, color_, x, y, r, radius_, config_.centre);
  };
  const cv::Rect mask_rect = planes_.rect;  // the window mask_ segmented
  BallCentre bc = rim_from(cx, cy, r0);
  bool from_expected = false;  // the rim found round another start: no colour adaptation
  // A blob the window cuts, its rim not found round its centroid: the ball run together with
  // something of its colour (its shadow on a floor of its hue). Where the ball was expected,
  // its rim may still be found; the merged blob's centroid is not the ball's centre.
  // Only for a slow ball (a fast one's prediction breaks at an impact), a blob the frame's
  // border does not cut (a ball half out of view has no rim to find there) and one as wide
  // and as tall as the ball at least (else the ball is not all in it: a sliver of it).
  if (!bc.ok && blob.touches_edge && radius_ > 0 && expected_motion_px_ < 0.5 * radius_ &&
      !CutByRoiBorder(blob.box) && std::min(blob.box.width, blob.box.height) >= 1.8 * radius_ &&
      std::hypot(expected.x - cx, expected.y - cy) > 0.25 * radius_) {
    const BallCentre at_expected = rim_from(expected.x, expected.y, radius_);
    if (at_expected.ok && !at_expected.cut && SizeMatches(at_expected.r, radius_)) bc = at_expected, from_expected = true;
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
  const bool may_be_close_up = radius_ <= 0 || IsCloseUp(radius_);
  if (!from_expected && may_be_close_up &&
      (!bc.ok || loose(bc) || (radius_ > 0 && !bc.cut && !SizeMatches(bc.r, radius_)))) {
    const cv::Rect box = cv::Rect(blob.box) - mask_rect.tl();
    const InscribedDisc disc = LargestInscribedDisc(
        mask_, box, blob.box.x <= roi_.x, blob.box.y <= roi_.y, blob.box.x + blob.box.width >= roi_.br().x,
        blob.box.y + blob.box.height >= roi_.br().y);
    const double dx = mask_rect.x + disc.cx, dy = mask_rect.y + disc.cy;
    const double ref_r = radius_ > 0 ? radius_ : disc.r;
    if (disc.ok && IsCloseUp(ref_r) && disc.r > 0.5 * ref_r && std::hypot(dx - cx, dy - cy) > 0.1 * ref_r) {
      const BallCentre at_disc = rim_from(dx, dy, ref_r);
      const bool fits = at_disc.ok && (radius_ <= 0 || at_disc.cut || SizeMatches(at_disc.r, radius_));
      if (fits && (!bc.ok || at_disc.rms < bc.rms)) bc = at_disc, from_expected = true;
    }
  }
  float score;
  bool shapeless = false;
  if (bc.ok) {
    if (radius_ > 0 && !bc.cut && !SizeMatches(bc.r, radius_))
      return false;
    score = static_cast<float>(bc.valid_rays * bc.inlier_fraction);
  } else if (blob.touches_edge) {
    // Ball cut by the frame or ROI border: the blob is all there is.
    bc.cx = cx, bc.cy = cy, bc.r = r0;
    score = 0.2f;
    shapeless = CutByRoiBorder(blob.box);
  } else if (radius_ > 0 && std::min(blob.box.width, blob.box.height) > 1.4 * radius_ &&
             std::min(blob.box.width, blob.box.height) < 2.6 * radius_) {
    // Not round but ball-sized across: a ball smeared by motion blur (slow shutters). The
    // box centre is the centre of the smear, i.e. of the ball at mid-exposure.
    bc.cx = blob.box.x + 0.5 * (blob.box.width - 1);
    bc.cy = blob.box.y + 0.5 * (blob.box.height - 1);
    bc.r = radius_;
    score = 0.3f;
  } else {
    return false;
  }
  shapeless_ = shapeless;
  obs->found = true;
  obs->x = blob.box.x;
  obs->y = blob.box.y;
  obs->w = blob.box.width;
  obs->h = blob.box.height;
  obs->cx = static_cast<float>(bc.cx);
  obs->cy = static_cast<float>(bc.cy);
  obs->radius_px = static_cast<float>(bc.r);
  obs->pixel_count = blob.pixels;
  obs->aspect_ratio = blob.box.height > 0 ? blob.box.width / blob.box.height : 0;
  obs->score = std::clamp(score, 0.0f, 1.0f);
  // Adaptation is slow by design: every 4th good frame, 4x the rate, same time constant.
  // Not from a rim found only at the prediction: its surroundings are the patch it ran into.
  if (!luma_ && !looking_back_ && bc.ok && !bc.cut && !from_expected && bc.inlier_fraction > 0.8 &&
      config_.adapt_rate > 0 &&
      ++adapt_tick_ % 4 == 0)
    Adapt(bc.cx, bc.cy, bc.r);
  return true;
}

void Tracker::Planes(const Frame& frame, cv::Rect rect, int step, double blur_sigma_px,
                     YccPlanes* out) {
  if (luma_)
    luma_->ContrastPlanes(rect, step, blur_sigma_px, out);
  else
    ExtractYcc(frame, rect, step, blur_sigma_px, out);
}

bool Tracker::PredictInFrame(double t, double* x, double* y, double* speed) const {
  if (!predictor_.Predict(t, x, y, speed)) return false;
  *x += cam_x_, *y += cam_y_;
  return true;
}

cv::Rect2d Tracker::WhereBallMayBe(double t) const {
  if (radius_ <= 0 || lost_ > 2) return {};
  // From where it was last seen to where it is predicted: a fast ball crosses tiles a frame.
  double px = last_cx_, py = last_cy_;
  PredictInFrame(t, &px, &py);
  const double m = 1.5 * radius_ + 8;
  return cv::Rect2d(std::min(px, last_cx_) - m, std::min(py, last_cy_) - m, std::abs(px - last_cx_) + 2 * m,
                    std::abs(py - last_cy_) + 2 * m);
}

void Tracker::SetLumaFrame(const Frame& frame) {
  const double followed_r = FollowedRadius();
  luma_->SetFrame(frame, IsCloseUp(followed_r) ? followed_r : 0);
}

void Tracker::StartLumaMode(int polarity, double contrast_luma) {
  LumaContrastParams params = config_.luma;
  params.polarity = polarity;
  // A ball that stands out of its surroundings by little (a white ball on a pale wall, a
  // camera's flat tone curve) stands out of the background model by about half as much: the
  // thresholds scale down with it, to a floor above the noise.
  const double scale = contrast_luma > 0 ? std::clamp(config_.luma_contrast_share * contrast_luma /
                                                          params.min_contrast_luma, config_.luma_min_scale, 1.0)
                                         : 1.0;
  params.min_contrast_luma *= scale;
  params.clamp_luma *= scale;
  luma_ = std::make_unique<LumaContrast>(params);
  color_ = LumaContrast::BallModel(params, config_.color);
  how_ = fmt::format(": brightness, {} than a background model by >= {:.0f} luma (clamped at {:.0f})",
                     polarity > 0 ? "brighter" : polarity < 0 ? "darker" : "brighter or darker", params.min_contrast_luma,
                     params.clamp_luma);
}

void Tracker::Adapt(double cx, double cy, double r) {
  const float floor = static_cast<float>(config_.color.luma_floor);
  const float min_luma = static_cast<float>(config_.color.min_luma);
  double in_u = 0, in_v = 0, out_u = 0, out_v = 0;
  int in_n = 0, out_n = 0;
  const double r_in2 = 0.6 * 0.6 * r * r, r_lo2 = 1.4 * 1.4 * r * r, r_hi2 = 1.9 * 1.9 * r * r;
  for (int j = 0; j < planes_.y.rows; ++j) {
    const double dy = planes_.rect.y + j - cy;
    if (dy * dy > r_hi2) continue;
    const float* py = planes_.y.ptr<float>(j);
    const float* pu = planes_.u.ptr<float>(j);
    const float* pv = planes_.v.ptr<float>(j);
    for (int i = 0; i < planes_.y.cols; ++i) {
      const double dx = planes_.rect.x + i - cx;
      const double d2 = dx * dx + dy * dy;
      if (py[i] < min_luma || (d2 > r_in2 && d2 < r_lo2) || d2 > r_hi2) continue;
      const float inv = 1.0f / std::max(py[i], floor);
      if (d2 <= r_in2) in_u += pu[i] * inv, in_v += pv[i] * inv, ++in_n;
      else out_u += pu[i] * inv, out_v += pv[i] * inv, ++out_n;
    }
  }
  if (in_n < 5) return;
  in_u /= in_n, in_v /= in_n;
  const double tol = color_.tolerance();
  if (std::hypot(in_u - color_.nu(), in_v - color_.nv()) > tol) return;
  if (out_n > 0) {
    out_u /= out_n, out_v /= out_n;
    // Surroundings that look like the ball: adapting now could drift onto them.
    if (std::hypot(out_u - color_.nu(), out_v - color_.nv()) < 1.5 * tol) return;
  }
  color_.AdaptTowards(in_u, in_v, std::min(1.0, 4 * config_.adapt_rate), anchor_,
                      config_.adapt_max_drift * std::hypot(anchor_.nu(), anchor_.nv()));
}

std::string Tracker::Describe() const {
  std::string text = fmt::format("tracker: {}; found in {} of {} frames, {} full-frame searches", how_,
                                 found_ + found_earlier_, frames_, acquisitions_);
  if (found_earlier_ > 0) text += fmt::format("; {} of those found looking back from a later sighting", found_earlier_);
  if (dropped_locks_ > 0)
    text += fmt::format("; automatic locks dropped or replaced before one was ballistic: {}", dropped_locks_);
  if (camera_.moving()) {
    text += fmt::format("; the camera moved (held in a hand?): up to {:.1f} px from where it started, taken out of the "
                        "ball's track",
                        camera_.max_offset());
    if (camera_.unmeasured() > 0) text += fmt::format(" ({} frames not measurable)", camera_.unmeasured());
  }
  return text;
}

}  // namespace bouncefit
