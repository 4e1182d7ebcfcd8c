#include "track/ball_finder.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "track/change_map.h"
#include "track/mask_components.h"
#include "track/shrink.h"

namespace bouncefit {

namespace {

// Contrasts against the surroundings in comparable units: this much luma (0-255) stands out
// as much as this much chroma/luma.
constexpr double kLumaContrastUnit = 50;
constexpr double kChromaContrastUnit = 0.25;

double MedianOf(std::vector<float>& v) {
  if (v.empty()) return 0;
  auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

struct Stats {
  double y = 0, nu = 0, nv = 0;
  int n = 0;
};

// Medians of luma and luma-normalised chroma over the pixels of `ycc` where `take` holds.
template <typename Take>
Stats StatsOf(const cv::Mat& ycc, cv::Rect rect, double luma_floor, Take take) {
  std::vector<float> ys, us, vs;
  rect &= cv::Rect(0, 0, ycc.cols, ycc.rows);
  for (int j = rect.y; j < rect.y + rect.height; ++j) {
    const uint8_t* p = ycc.ptr<uint8_t>(j);
    for (int i = rect.x; i < rect.x + rect.width; ++i) {
      if (!take(i, j)) continue;
      const float y = p[3 * i], inv = 1.0f / std::max(y, static_cast<float>(luma_floor));
      ys.push_back(y);
      vs.push_back((p[3 * i + 1] - 128.0f) * inv);
      us.push_back((p[3 * i + 2] - 128.0f) * inv);
    }
  }
  Stats s;
  s.n = static_cast<int>(ys.size());
  s.y = MedianOf(ys);
  s.nu = MedianOf(us);
  s.nv = MedianOf(vs);
  return s;
}

// Like StatsOf, over the half of the pixels whose colour differs most from `ref` (chroma
// distance for the chroma medians, luma distance for the luma median).
template <typename Take>
Stats DistinctStats(const cv::Mat& ycc, cv::Rect rect, double luma_floor, const Stats& ref, Take take) {
  struct Px {
    float y, u, v;
  };
  std::vector<Px> px;
  rect &= cv::Rect(0, 0, ycc.cols, ycc.rows);
  for (int j = rect.y; j < rect.y + rect.height; ++j) {
    const uint8_t* p = ycc.ptr<uint8_t>(j);
    for (int i = rect.x; i < rect.x + rect.width; ++i) {
      if (!take(i, j)) continue;
      const float y = p[3 * i], inv = 1.0f / std::max(y, static_cast<float>(luma_floor));
      px.push_back({y, (p[3 * i + 2] - 128.0f) * inv, (p[3 * i + 1] - 128.0f) * inv});
    }
  }
  Stats s;
  s.n = static_cast<int>(px.size());
  if (px.empty()) return s;
  const size_t half = std::max<size_t>(1, px.size() / 2);
  // Squared distances: the order is the same, and hypot is slow.
  auto chroma_d = [&](const Px& a) {
    const float du = a.u - static_cast<float>(ref.nu), dv = a.v - static_cast<float>(ref.nv);
    return du * du + dv * dv;
  };
  std::nth_element(px.begin(), px.begin() + static_cast<long>(half - 1), px.end(),
                   [&](const Px& a, const Px& b) { return chroma_d(a) > chroma_d(b); });
  std::vector<float> us, vs, ys;
  for (size_t i = 0; i < half; ++i) us.push_back(px[i].u), vs.push_back(px[i].v);
  std::nth_element(px.begin(), px.begin() + static_cast<long>(half - 1), px.end(),
                   [&](const Px& a, const Px& b) { return std::abs(a.y - ref.y) > std::abs(b.y - ref.y); });
  for (size_t i = 0; i < half; ++i) ys.push_back(px[i].y);
  s.nu = MedianOf(us);
  s.nv = MedianOf(vs);
  s.y = MedianOf(ys);
  return s;
}

struct SegBlob {
  bool ok = false;
  cv::Point2d centre;  // work pixels
  double r = 0;        // equivalent radius, work pixels
  double roundness = 0;
  cv::Rect box;        // work pixels
};

// The round blob of pixels passing `is_ball` within `half` of `centre` in `ycc`: the one
// overlapping label `k` of `labels` most (when given), else the one nearest the centre. Not
// ok when it runs on beyond the window (part of something larger) or is not round.
template <typename IsBall>
SegBlob SegmentNear(const cv::Mat& ycc, cv::Point2d centre, double half, IsBall is_ball,
                    const cv::Mat* labels, int k) {
  SegBlob out;
  const int W = ycc.cols, H = ycc.rows;
  const cv::Rect win = cv::Rect(static_cast<int>(centre.x - half), static_cast<int>(centre.y - half),
                                static_cast<int>(2 * half + 1), static_cast<int>(2 * half + 1)) &
                       cv::Rect(0, 0, W, H);
  if (win.width < 3 || win.height < 3) return out;
  cv::Mat seg(win.size(), CV_8U);
  for (int j = 0; j < win.height; ++j) {
    const uint8_t* p = ycc.ptr<uint8_t>(win.y + j) + 3 * win.x;
    uint8_t* q = seg.ptr<uint8_t>(j);
    for (int i = 0; i < win.width; ++i, p += 3) q[i] = is_ball(p) ? 255 : 0;
  }
  cv::Mat sl, ss, sc;
  const int sn = ComponentsWithStats(seg, &sl, &ss, &sc);
  int best = 0;
  double best_key = 0;
  std::vector<int> overlap(sn, 0);
  if (labels)
    for (int j = 0; j < win.height; ++j)
      for (int i = 0; i < win.width; ++i)
        if (labels->at<int>(win.y + j, win.x + i) == k) ++overlap[sl.at<int>(j, i)];
  for (int s = 1; s < sn; ++s) {
    if (ss.at<int>(s, cv::CC_STAT_AREA) < 4) continue;
    const double key = labels ? overlap[s]
                              : -std::hypot(win.x + sc.at<double>(s, 0) - centre.x, win.y + sc.at<double>(s, 1) - centre.y);
    if (labels && overlap[s] == 0) continue;
    if (best == 0 || key > best_key) best = s, best_key = key;
  }
  if (best <= 0) return out;
  const int bx = ss.at<int>(best, cv::CC_STAT_LEFT), by = ss.at<int>(best, cv::CC_STAT_TOP);
  const int bw = ss.at<int>(best, cv::CC_STAT_WIDTH), bh = ss.at<int>(best, cv::CC_STAT_HEIGHT);
  const int area = ss.at<int>(best, cv::CC_STAT_AREA);
  // Touching the window where the window is not the frame edge: it runs on beyond.
  if ((bx == 0 && win.x > 0) || (by == 0 && win.y > 0) ||
      (bx + bw == win.width && win.x + win.width < W) || (by + bh == win.height && win.y + win.height < H))
    return out;
  const double aspect = static_cast<double>(std::max(bw, bh)) / std::max(1, std::min(bw, bh));
  const double fill = area / (static_cast<double>(bw) * bh);
  if (aspect > 2.6 || fill < 0.45 || fill > 0.95) return out;
  out.ok = true;
  out.centre = {win.x + sc.at<double>(best, 0), win.y + sc.at<double>(best, 1)};
  out.r = std::sqrt(area / std::numbers::pi);
  out.roundness = std::max(0.05, 1 - 2 * std::abs(fill - 0.785) - 0.3 * (aspect - 1));
  out.box = cv::Rect(win.x + bx, win.y + by, bw, bh);
  return out;
}

}  // namespace

std::string BallCandidate::Why() const {
  const std::string colour = weaker_colour > 0
                                 ? fmt::format("its colour only {:.2f} chroma/luma from theirs", weaker_colour)
                                 : std::string("no colour of its own");
  if (by_luma)
    return fmt::format("a round blob that moved, {} than its surroundings by {:.0f} luma ({}), at {:.0f},{:.0f}, radius "
                       "{:.1f} px",
                       polarity > 0 ? "brighter" : "darker", contrast, colour, x, y, r);
  return fmt::format("a round blob that moved, its colour {:.2f} chroma/luma from its surroundings' colour, at "
                     "{:.0f},{:.0f}, radius {:.1f} px",
                     contrast, x, y, r);
}

BallFinder::Work& BallFinder::Push(const Frame& frame, cv::Rect roi) {
  if (roi != roi_) history_.clear(), roi_ = roi;
  shrink_ = 1;
  while (static_cast<double>(roi.area()) / (shrink_ * shrink_) > params_.max_work_pixels && shrink_ < 16)
    shrink_ *= 2;
  Work w;
  if (history_.size() >= kHistory) {
    // Reuse the oldest frame's buffers: fresh ones of this size cost page faults each time
    // (not a frame's own memory: that is the frame's, never written here).
    if (!history_.front().raw_borrowed) w.raw = std::move(history_.front().raw);
    w.spare = std::move(history_.front().ycc);
    history_.pop_front();
  }
  w.t = static_cast<double>(frame.utime) * 1e-6;
  w.format = frame.format;
  history_.push_back(std::move(w));
  return history_.back();
}

void BallFinder::Remember(const Frame& frame, cv::Rect roi) {
  // Kept as delivered, shrunk and converted only if a Find compares it: most frames of a
  // holding lock never are. A copy, unless the frame's memory is its own (a copy of every
  // frame, twice, was an eighth of a held ball's tracking time).
  Work& w = Push(frame, roi);
  if (frame.owns_image) {
    w.raw = frame.image(roi);
    w.raw_borrowed = true;
  } else {
    frame.image(roi).copyTo(w.raw);
  }
}

const cv::Mat& BallFinder::Ycc(Work& w) {
  if (w.ycc.empty()) ToYcc(w.raw, w.format, &w.spare), w.ycc = std::move(w.spare);
  return w.ycc;
}

const PictureProfiles& BallFinder::Profiles(Work& w) {
  if (w.profiles.empty()) w.profiles = ProfilesOf(Ycc(w));
  return w.profiles;
}

void BallFinder::ChangeAgainst(const cv::Mat& b, const cv::Mat& other, const PictureShift& shift,
                               cv::Mat& d) {
  if (!shift.moved()) {
    ChangeMap(b, other, d);
    return;
  }
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, shift.dx, 0, 1, shift.dy);
  cv::warpAffine(other, moved_, m, other.size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
  ChangeMap(b, moved_, d);
}

void BallFinder::ToYcc(const cv::Mat& image, PixelFormat format, cv::Mat* ycc) {
  cv::Mat bgr = image;
  if (format == PixelFormat::kYuyv) cv::cvtColor(image, bgr_, cv::COLOR_YUV2BGR_YUYV), bgr = bgr_;
  if (shrink_ > 1)
    ShrinkByArea(bgr, &small_, cv::Size(image.cols / shrink_, image.rows / shrink_));  // cv::INTER_AREA's
  else
    cv::GaussianBlur(bgr, small_, cv::Size(3, 3), 0.8);
  cv::cvtColor(small_, *ycc, cv::COLOR_BGR2YCrCb);
}

std::vector<BallCandidate> BallFinder::Find(const Frame& frame, cv::Rect roi) {
  std::vector<BallCandidate> out;
  Work& now = Push(frame, roi);
  ToYcc(frame.image(roi), frame.format, &now.spare);
  now.ycc = std::move(now.spare);

  // C = now, B = at least lag_s before it, A = at least lag_s before B.
  const int nc = static_cast<int>(history_.size()) - 1;
  int nb = nc - 1;
  while (nb > 0 && history_[nc].t - history_[nb].t < params_.lag_s && nc - nb < 8) --nb;
  const int lag = nc - nb;
  const int na = nb - lag;
  if (na < 0) return out;
  const cv::Mat& A = Ycc(history_[na]);
  const cv::Mat& B = Ycc(history_[nb]);
  const cv::Mat& C = Ycc(history_[nc]);
  // A hand-held camera: the older and newer frames moved onto the middle one's picture.
  const PictureShift shift_a = MeasurePictureShift(Profiles(history_[na]), Profiles(history_[nb]));
  const PictureShift shift_c = MeasurePictureShift(Profiles(history_[nc]), Profiles(history_[nb]));
  ChangeAgainst(B, A, shift_a, dba_);
  ChangeAgainst(B, C, shift_c, dbc_);
  const cv::Mat& dba = dba_;
  const cv::Mat& dbc = dbc_;

  // Noise sets the threshold: most of the frame is still, so the median change is noise.
  const double th = std::max(params_.min_change, 3.0 * MedianOfEvery4th(dbc) + 6);
  cv::Mat changed = dbc > th, moved = (dba > th) & changed;
  if (cv::countNonZero(changed) > params_.max_changed_share * changed.total()) return out;
  CloseByCross(moved);
  cv::Mat any_change = (dba > th) | changed;

  cv::Mat box_labels, stats, centroids;
  cv::Rect moved_box;
  const int n = MaskComponents(moved, &box_labels, &stats, &centroids, &moved_box);
  if (n <= 1) return out;
  labels_.create(moved.size(), CV_32S);  // in work pixels, as read below
  labels_.setTo(0);
  box_labels.copyTo(labels_(moved_box));
  const cv::Mat& labels = labels_;
  const int W = B.cols, H = B.rows;
  const double min_r = params_.min_radius_px;
  std::vector<int> order;
  for (int k = 1; k < n; ++k) {
    const int bw = stats.at<int>(k, cv::CC_STAT_WIDTH), bh = stats.at<int>(k, cv::CC_STAT_HEIGHT);
    if (std::max(bw, bh) < 2 * min_r || std::max(bw, bh) > 0.45 * std::min(W, H)) continue;
    if (stats.at<int>(k, cv::CC_STAT_AREA) < min_r * min_r * 2) continue;
    order.push_back(k);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return stats.at<int>(a, cv::CC_STAT_AREA) > stats.at<int>(b, cv::CC_STAT_AREA);
  });
  if (order.size() > 8) order.resize(8);

  const double floor = color_.luma_floor;
  for (int k : order) {
    const cv::Rect box(stats.at<int>(k, cv::CC_STAT_LEFT), stats.at<int>(k, cv::CC_STAT_TOP),
                       stats.at<int>(k, cv::CC_STAT_WIDTH), stats.at<int>(k, cv::CC_STAT_HEIGHT));
    const double cx = centroids.at<double>(k, 0), cy = centroids.at<double>(k, 1);
    const double rb = 0.5 * std::max(box.width, box.height);
    // What moved, as it looks in the middle frame, against the still ring around it.
    const double r_in = rb + 2, r_out = 2 * rb + 4;
    const cv::Rect ring_box(static_cast<int>(cx - r_out), static_cast<int>(cy - r_out),
                            static_cast<int>(2 * r_out + 1), static_cast<int>(2 * r_out + 1));
    const Stats around = StatsOf(B, ring_box, floor, [&](int i, int j) {
      const double d2 = (i - cx) * (i - cx) + (j - cy) * (j - cy);
      return d2 >= r_in * r_in && d2 <= r_out * r_out && !any_change.at<uint8_t>(j, i);
    });
    if (around.n < 12) continue;
    // The ball's pixels that differ most from the ring: the moving region's rim blends
    // ball and background (motion blur, a crescent when it moved less than its size).
    const Stats ball = DistinctStats(B, box, floor, around, [&](int i, int j) { return labels.at<int>(j, i) == k; });
    BallCandidate c;
    ColorModel model;
    const double luma_contrast = ball.y - around.y;
    // Chooses the cue for a ball of chroma `nu`, `nv`: what sets it apart the most (a white
    // ball under warm light has a faint tint that a black cloth lacks, and a far larger step
    // of brightness). False: neither does, or its colour takes in the ring.
    auto choose = [&](double nu, double nv) {
      c = BallCandidate();
      const double chroma_contrast = std::hypot(nu - around.nu, nv - around.nv);
      const bool has_colour = chroma_contrast >= params_.min_chroma_contrast &&
                              std::hypot(nu, nv) >= params_.min_ball_chroma;
      const bool brightness_stronger = std::abs(luma_contrast) / kLumaContrastUnit >=
                                           2 * chroma_contrast / kChromaContrastUnit &&
                                       std::abs(luma_contrast) >= params_.min_luma_contrast;
      if (has_colour && !brightness_stronger) {
        model = ColorModel(nu, nv, color_);
        model.KeepOut(around.nu, around.nv);
        // The ring must not match the ball's colour: a model that takes in the surroundings
        // cannot separate the ball from them.
        if (std::hypot(around.nu - nu, around.nv - nv) <= model.tolerance()) return false;
        c.contrast = chroma_contrast;
      } else if (std::abs(luma_contrast) >= params_.min_luma_contrast) {
        c.by_luma = true;
        c.polarity = luma_contrast > 0 ? 1 : -1;
        c.contrast = std::abs(luma_contrast);
        if (has_colour) c.weaker_colour = chroma_contrast;
      } else {
        return false;
      }
      return true;
    };
    if (!choose(ball.nu, ball.nv)) continue;
    // Segment the neighbourhood with that colour (or brightness): the ball must come out as a
    // round blob of its own, inside the window, not part of something larger.
    const float level = static_cast<float>(around.y + 0.5 * luma_contrast);
    auto is_ball = [&](const uint8_t* p) {
      if (c.by_luma) return c.polarity > 0 ? p[0] >= level : p[0] <= level;
      return model.Matches(p[0], p[2] - 128.0f, p[1] - 128.0f);
    };
    auto fits = [&](const SegBlob& b) { return b.ok && b.r >= min_r && b.r <= 1.6 * rb + 1; };
    SegBlob in_b = SegmentNear(B, {cx, cy}, 2.5 * rb + 3, is_ball, &labels, k);
    if (!fits(in_b)) continue;
    if (c.by_luma) {
      // Brightness chosen on what moved: a ball that moved less than its size leaves a thin
      // crescent of its leading (often shaded) side, blended with the background, where its
      // colour is diluted or lost. Its colour over the whole blob found by brightness decides
      // again, and is followed if it then wins and segments the ball.
      const Stats body = StatsOf(B, in_b.box, floor, [&](int i, int j) { return is_ball(B.ptr<uint8_t>(j) + 3 * i); });
      const BallCandidate by_brightness = c;
      if (body.n >= 4 && choose(body.nu, body.nv) && !c.by_luma) {
        const SegBlob by_colour = SegmentNear(B, {cx, cy}, 2.5 * rb + 3, is_ball, &labels, k);
        if (fits(by_colour)) in_b = by_colour;
        else c = by_brightness;
      } else {
        c = by_brightness;
      }
    }
    c.roundness = in_b.roundness;
    if (!c.by_luma) {
      const Stats blob = StatsOf(B, in_b.box, floor, [&](int i, int j) {
        const uint8_t* p = B.ptr<uint8_t>(j) + 3 * i;
        return is_ball(p);
      });
      c.color = ColorModel(blob.nu, blob.nv, color_);
      c.color.KeepOut(around.nu, around.nv);
    }
    // Where it is now: the same blob near there in the newest frame (it moved for `lag`
    // frames), else where it was.
    const SegBlob in_c = SegmentNear(C, in_b.centre, 4 * in_b.r + 4, is_ball, nullptr, 0);
    const bool seen_now = in_c.ok && std::abs(in_c.r - in_b.r) < 0.4 * in_b.r + 1;
    const cv::Point2d at = seen_now ? in_c.centre : in_b.centre;
    const double s = shrink_;
    c.x = roi.x + (at.x + 0.5) * s - 0.5;
    c.y = roi.y + (at.y + 0.5) * s - 0.5;
    c.r = in_b.r * s;
    c.t = history_[seen_now ? nc : nb].t;
    const double area = std::numbers::pi * in_b.r * in_b.r;
    const double contrast_norm = c.by_luma ? c.contrast / kLumaContrastUnit : c.contrast / kChromaContrastUnit;
    c.score = c.roundness * std::min(2.0, contrast_norm) * std::sqrt(area) * s;  // frame pixels: finders of any size compare
    out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const BallCandidate& a, const BallCandidate& b) { return a.score > b.score; });
  return out;
}

}  // namespace bouncefit
