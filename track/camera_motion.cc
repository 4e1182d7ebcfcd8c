#include "track/camera_motion.h"

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit {
namespace {

constexpr double kSharpness = 0.5;  // the best shift's mismatch under this share of the median

constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();  // a bin the ball may cover

// The profile's steps, smoothed by a binomial of 5 taps (sigma 1 bin): sharp edges would
// match at whole shifts only, and a camera moves by fractions too. NaN stays NaN.
void ToSteps(std::vector<float>& p) {
  if (p.size() < 6) return p.clear();
  std::vector<float> d(p.size() - 1);
  for (size_t i = 0; i < d.size(); ++i) d[i] = p[i + 1] - p[i];
  p.resize(d.size() - 4);
  for (size_t i = 0; i < p.size(); ++i)
    p[i] = (d[i] + 4 * d[i + 1] + 6 * d[i + 2] + 4 * d[i + 3] + d[i + 4]) / 16;
}

// Mean |step| of a profile of steps (its known bins), luma; 0 when under half are known.
double Texture(const std::vector<float>& steps) {
  double s = 0;
  size_t n = 0;
  for (float v : steps)
    if (!std::isnan(v)) s += std::abs(v), ++n;
  return 2 * n < steps.size() || n == 0 ? 0 : s / static_cast<double>(n);
}

struct TileShift {
  bool ok = false;
  int whole = 0;
  double refined = 0;
};

// Mean squared mismatch of a against b moved by d over their overlap, bins where either is
// unknown (weight 0) left out; +inf without overlap.
double Mismatch(const std::vector<float>& va, const std::vector<float>& wa, const std::vector<float>& vb,
                const std::vector<float>& wb, int d) {
  const int n = static_cast<int>(va.size());
  const int i0 = std::max(0, -d), i1 = std::min(n, n - d);
  float s = 0, m = 0;
  int i = i0;
#if CV_SIMD128
  cv::v_float32x4 vs = cv::v_setzero_f32(), vm = cv::v_setzero_f32();
  for (; i + 4 <= i1; i += 4) {
    const cv::v_float32x4 e = cv::v_load(&va[i]) - cv::v_load(&vb[i + d]);
    const cv::v_float32x4 w = cv::v_load(&wa[i]) * cv::v_load(&wb[i + d]);
    vs += e * e * w;
    vm += w;
  }
  s = cv::v_reduce_sum(vs), m = cv::v_reduce_sum(vm);
#endif
  for (; i < i1; ++i) {
    const float e = va[i] - vb[i + d], w = wa[i] * wb[i + d];
    s += e * e * w, m += w;
  }
  return m > 0 ? s / m : std::numeric_limits<double>::infinity();
}

// The least of cost[d] over [lo, hi] (d from -max_shift), ok when inside that range and well
// under the range's typical mismatch; refined by the parabola through it and its neighbours.
TileShift BestIn(const std::vector<double>& cost, int max_shift, int lo, int hi) {
  TileShift out;
  int best = lo;
  std::vector<double> range;
  for (int d = lo; d <= hi; ++d) {
    range.push_back(cost[d + max_shift]);
    if (cost[d + max_shift] < cost[best + max_shift]) best = d;
  }
  const auto mid = range.begin() + static_cast<long>(range.size() / 2);
  std::nth_element(range.begin(), mid, range.end());
  const double c0 = cost[best + max_shift];
  if (best == lo || best == hi || !(c0 < kSharpness * *mid)) return out;
  const double cm = cost[best + max_shift - 1], cp = cost[best + max_shift + 1];
  const double curve = cm - 2 * c0 + cp;
  out.ok = true;
  out.whole = best;
  out.refined = best + (curve > 0 ? std::clamp(0.5 * (cm - cp) / curve, -0.5, 0.5) : 0.0);
  return out;
}

// The shift d of b against a (b[i + d] ~ a[i]) with the least mean squared difference over
// the overlap, looked for first within a few bins of `expected` (the camera moves little
// from one frame to the next), then, if not found there, over the whole search.
TileShift BestShift(const std::vector<float>& a, const std::vector<float>& b, int max_shift,
                    double min_texture, int expected) {
  const int n = static_cast<int>(a.size());
  max_shift = std::min(max_shift, n / 3);  // a small picture's tiles: a shorter search
  if (n != static_cast<int>(b.size()) || max_shift < 4 || Texture(a) < min_texture ||
      Texture(b) < min_texture)
    return {};
  // Bins where either picture may show the ball are left out: values 0, weights 0.
  thread_local std::vector<float> va, wa, vb, wb;
  auto split = [&](const std::vector<float>& p, std::vector<float>& v, std::vector<float>& w) {
    v.resize(p.size()), w.resize(p.size());
    for (size_t i = 0; i < p.size(); ++i) w[i] = std::isnan(p[i]) ? 0.0f : 1.0f, v[i] = w[i] > 0 ? p[i] : 0.0f;
  };
  split(a, va, wa), split(b, vb, wb);
  constexpr int kNear = 6;
  std::vector<double> cost(2 * max_shift + 1, -1.0);
  auto costs = [&](int lo, int hi) {
    for (int d = lo; d <= hi; ++d)
      if (cost[d + max_shift] < 0) cost[d + max_shift] = Mismatch(va, wa, vb, wb, d);
  };
  const int lo = std::max(-max_shift, expected - kNear), hi = std::min(max_shift, expected + kNear);
  if (hi - lo >= kNear) {
    costs(lo, hi);
    const TileShift near = BestIn(cost, max_shift, lo, hi);
    if (near.ok) return near;
  }
  costs(-max_shift, max_shift);
  return BestIn(cost, max_shift, -max_shift, max_shift);
}

// A row added into 16-bit column sums, and a run of bytes summed: whole rows, so that a
// narrow tile's columns are summed sixteen at a time too (a tile 43 px wide left a quarter of
// its pixels to a scalar tail); a run's sum by sums of absolute differences from zero.
void AddBytes(const uint8_t* p, uint16_t* sums, int n) {
  int i = 0;
#if CV_SIMD128
  for (; i + 16 <= n; i += 16) {
    cv::v_uint16x8 lo, hi;
    cv::v_expand(cv::v_load(p + i), lo, hi);
    cv::v_store(sums + i, cv::v_load(sums + i) + lo);
    cv::v_store(sums + i + 8, cv::v_load(sums + i + 8) + hi);
  }
#endif
  for (; i < n; ++i) sums[i] = static_cast<uint16_t>(sums[i] + p[i]);
}

uint32_t SumBytes(const uint8_t* p, int n) {
  uint32_t s = 0;
  int i = 0;
#if CV_SIMD128
  const cv::v_uint8x16 zero = cv::v_setzero_u8();
  for (; i + 16 <= n; i += 16) s += cv::v_reduce_sad(cv::v_load(p + i), zero);
#endif
  for (; i < n; ++i) s += p[i];
  return s;
}

// A plane's sums in one pass: each band of rows' column sums (16 bits for up to 256 rows,
// then 32) into col_sums[band * cols + x], and each row's sum over each run of columns into
// row_sums[run * rows + y]; bands and runs between the given edges.
void PlaneSums(const cv::Mat& plane, const std::vector<int>& x_edges, const std::vector<int>& y_edges,
               std::vector<int32_t>* col_sums, std::vector<int32_t>* row_sums) {
  const int W = plane.cols, H = plane.rows;
  const int runs = static_cast<int>(x_edges.size()) - 1, bands = static_cast<int>(y_edges.size()) - 1;
  thread_local std::vector<uint16_t> col16;
  col_sums->assign(static_cast<size_t>(bands) * W, 0);
  row_sums->assign(static_cast<size_t>(runs) * H, 0);
  col16.assign(static_cast<size_t>(W), 0);
  auto flush = [&](int band) {
    int32_t* c = &(*col_sums)[static_cast<size_t>(band) * W];
    for (size_t i = 0; i < col16.size(); ++i) c[i] += col16[i];
    std::fill(col16.begin(), col16.end(), 0);
  };
  for (int band = 0; band < bands; ++band) {
    for (int y = y_edges[band]; y < y_edges[band + 1]; ++y) {
      const uint8_t* p = plane.ptr<uint8_t>(y);
      AddBytes(p, col16.data(), W);
      for (int r = 0; r < runs; ++r)
        (*row_sums)[static_cast<size_t>(r) * H + y] =
            static_cast<int32_t>(SumBytes(p + x_edges[r], x_edges[r + 1] - x_edges[r]));
      if ((y - y_edges[band]) % 256 == 255) flush(band);
    }
    flush(band);
  }
}

}  // namespace

CameraProfiles CameraProfilesOf(const Frame& frame, const CameraMotionParams& params, cv::Rect2d ignore,
                                const cv::Mat* luma, double luma_gain, int luma_turn_cw_deg) {
  CameraProfiles out;
  const int W = frame.image.cols, H = frame.image.rows, t = params.tiles;
  out.size = frame.image.size();
  if (W < 2 * t || H < 2 * t) return out;
  const int bin = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(W) * H / params.cell_pixels)));
  out.bin = bin;
  // Every row and column of the luma summed (a subsample aliases: a ruler's ticks, a tiled
  // floor; one row in two on a 1080p clip flipped the detection of a few shaken copies):
  // each band of tiles' column sums, each row's sum per column of tiles. Of the luma given
  // (the decoder's own, or a brightness lock's), else converted here (OpenCV's BT.601
  // weights).
  const int turn = luma_turn_cw_deg;
  const bool across = turn == 90 || turn == 270;  // the plane as stored: W x H transposed
  const cv::Size stored = across ? cv::Size(H, W) : cv::Size(W, H);
  thread_local cv::Mat converted;
  if (!luma || luma->size() != stored || luma->type() != CV_8U ||
      (turn != 0 && turn != 90 && turn != 180 && turn != 270)) {
    if (frame.format == PixelFormat::kYuyv)
      cv::extractChannel(frame.image, converted, 0);
    else
      cv::cvtColor(frame.image, converted, cv::COLOR_BGR2GRAY);
    luma = &converted;
    luma_gain = 1;
  }
  std::vector<int> x_edges(t + 1), y_edges(t + 1);
  for (int k = 0; k <= t; ++k) x_edges[k] = k * W / t, y_edges[k] = k * H / t;
  // The upright picture's sums: col_sums[band * W + x] over its band's rows, row_sums[tx * H
  // + y] over its tile column. A plane stored turned is summed as it lies, its bands and runs
  // the upright tiles' edges carried over, and its sums read back: across a quarter turn the
  // upright column sums are its row sums and the reverse; from the mirrored end where the
  // turn reverses an axis.
  thread_local std::vector<int32_t> col_sums, row_sums, col_s, row_s;
  auto mirrored = [t](const std::vector<int>& e, int n) {
    std::vector<int> m(t + 1);
    for (int k = 0; k <= t; ++k) m[k] = n - e[t - k];
    return m;
  };
  if (turn == 0 || luma == &converted) {
    PlaneSums(*luma, x_edges, y_edges, &col_sums, &row_sums);
  } else {
    // A turn swaps the axes (90, 270) and reverses x (90, 180) or y (180, 270): the stored
    // plane's runs lie along the upright axis it keeps as x, mirrored where that is reversed.
    const bool rev_x = turn == 90 || turn == 180, rev_y = turn == 180 || turn == 270;
    const std::vector<int> xm = rev_x ? mirrored(x_edges, W) : x_edges;
    const std::vector<int> ym = rev_y ? mirrored(y_edges, H) : y_edges;
    PlaneSums(*luma, across ? ym : xm, across ? xm : ym, &col_s, &row_s);
    // dst[b * n + i] = src at band b and index i, either reversed.
    auto read_back = [t](const std::vector<int32_t>& src, int n, bool rev_band, bool rev_i,
                         std::vector<int32_t>* dst) {
      dst->resize(static_cast<size_t>(t) * n);
      for (int b = 0; b < t; ++b)
        for (int i = 0; i < n; ++i)
          (*dst)[static_cast<size_t>(b) * n + i] =
              src[static_cast<size_t>(rev_band ? t - 1 - b : b) * n + (rev_i ? n - 1 - i : i)];
    };
    read_back(across ? row_s : col_s, W, rev_y, rev_x, &col_sums);
    read_back(across ? col_s : row_s, H, rev_x, rev_y, &row_sums);
  }
  for (int ty = 0; ty < t; ++ty)
    for (int tx = 0; tx < t; ++tx) {
      const int x0 = x_edges[tx], x1 = x_edges[tx + 1], y0 = y_edges[ty], y1 = y_edges[ty + 1];
      std::vector<float> cols((x1 - x0) / bin), rows((y1 - y0) / bin);
      const int band_rows = y1 - y0;
      const int32_t* c = &col_sums[static_cast<size_t>(ty) * W];
      for (size_t i = 0; i < cols.size(); ++i) {
        int s = 0;
        for (int k = 0; k < bin; ++k) s += c[x0 + static_cast<int>(i) * bin + k];
        cols[i] = static_cast<float>(luma_gain * s / (bin * band_rows));
      }
      const int32_t* r = &row_sums[static_cast<size_t>(tx) * H];
      for (size_t j = 0; j < rows.size(); ++j) {
        int s = 0;
        for (int k = 0; k < bin; ++k) s += r[y0 + static_cast<int>(j) * bin + k];
        rows[j] = static_cast<float>(luma_gain * s / (bin * (x1 - x0)));
      }
      // Where the ball may be, the tile's columns and rows are not the scene's: unknown.
      const cv::Rect2d ball = ignore & cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
      if (ball.area() > 0) {
        for (size_t i = 0; i < cols.size(); ++i) {
          const double c0 = x0 + static_cast<double>(i * bin);
          if (c0 + bin > ball.x && c0 < ball.x + ball.width) cols[i] = kUnknown;
        }
        for (size_t j = 0; j < rows.size(); ++j) {
          const double r0 = y0 + static_cast<double>(j * bin);
          if (r0 + bin > ball.y && r0 < ball.y + ball.height) rows[j] = kUnknown;
        }
      }
      // Matched by their steps: a profile averaged over many rows is smooth, its mismatch
      // rises slowly with the shift; its steps (the picture's edges) make a sharp minimum.
      ToSteps(cols);
      ToSteps(rows);
      out.columns.push_back(std::move(cols));
      out.rows.push_back(std::move(rows));
    }
  return out;
}

namespace {

std::vector<TileShift> TileShifts(const std::vector<std::vector<float>>& a,
                                  const std::vector<std::vector<float>>& b, const CameraMotionParams& params,
                                  int expected) {
  std::vector<TileShift> out(std::min(a.size(), b.size()));
  for (size_t k = 0; k < out.size(); ++k)
    out[k] = BestShift(a[k], b[k], params.max_shift_bins, params.min_texture, expected);
  return out;
}

// The shift most tiles agree on (not those `skip` names): the whole shift with the most tiles
// within a bin of it (one shift's tiles fall either side of a half bin), refined by their median.
AxisShift Consensus(const std::vector<TileShift>& tiles, const std::vector<bool>& skip,
                    const CameraMotionParams& params) {
  AxisShift out;
  std::vector<double> told;
  for (size_t k = 0; k < tiles.size(); ++k)
    if (tiles[k].ok && !skip[k]) told.push_back(tiles[k].refined);
  out.told = static_cast<int>(told.size());
  int most = 0;
  std::vector<double> agreeing, best;
  for (const TileShift& candidate : tiles) {
    if (!candidate.ok) continue;
    agreeing.clear();
    for (double r : told)
      if (std::abs(r - candidate.whole) <= 1.0) agreeing.push_back(r);
    if (static_cast<int>(agreeing.size()) > most) most = static_cast<int>(agreeing.size()), best = agreeing;
  }
  if (most < params.min_agreeing || most < params.min_agreeing_share * out.told) return out;
  const auto mid = best.begin() + static_cast<long>(best.size() / 2);
  std::nth_element(best.begin(), mid, best.end());
  out.bins = *mid;
  out.whole = static_cast<int>(std::lround(out.bins));
  out.ok = true;
  return out;
}

// Tiles whose shift along an axis disagrees with that axis's consensus: the ball, a hand, a
// door that moved there, not the camera.
std::vector<bool> Disagreeing(const std::vector<TileShift>& tiles, const AxisShift& consensus) {
  std::vector<bool> out(tiles.size(), false);
  if (!consensus.ok) return out;
  for (size_t k = 0; k < tiles.size(); ++k)
    out[k] = tiles[k].ok && std::abs(tiles[k].refined - consensus.bins) > 1.0;
  return out;
}

}  // namespace

PictureMotion MeasurePictureMotion(const CameraProfiles& a, const CameraProfiles& b,
                                   const CameraMotionParams& params, cv::Point expected) {
  PictureMotion out;
  if (a.size != b.size || a.columns.size() != b.columns.size()) return out;
  const std::vector<TileShift> tx = TileShifts(a.columns, b.columns, params, expected.x);
  const std::vector<TileShift> ty = TileShifts(a.rows, b.rows, params, expected.y);
  const std::vector<bool> none(tx.size(), false);
  // Each axis on its own first; then each again without the tiles the other axis says
  // something else moved in (a tile of vertical stripes tells dx only: it is kept).
  const AxisShift x0 = Consensus(tx, none, params), y0 = Consensus(ty, none, params);
  out.x = Consensus(tx, Disagreeing(ty, y0), params);
  out.y = Consensus(ty, Disagreeing(tx, x0), params);
  return out;
}

void CameraMotion::Update(const Frame& frame, cv::Rect2d ignore, const cv::Mat* luma, double luma_gain,
                          int luma_turn_cw_deg) {
  if (!moving_ && frames_++ % std::max(1, params_.still_every) != 0) return;
  CameraProfiles now = CameraProfilesOf(frame, params_, ignore, luma, luma_gain, luma_turn_cw_deg);
  if (reference_.empty() || reference_.size != now.size) {
    // The first frame (or a new picture size): the scene as it is measured against.
    reference_ = now;
    previous_ = std::move(now);
    ref_dx_ = dx_, ref_dy_ = dy_;
    return;
  }
  // Where the last frame was against the reference: this one is near it, most often.
  const double bin = now.bin;
  const cv::Point expected(static_cast<int>(std::lround((dx_ - ref_dx_) / bin)),
                           static_cast<int>(std::lround((dy_ - ref_dy_) / bin)));
  const PictureMotion m = MeasurePictureMotion(reference_, now, params_, expected);
  const AxisShift& sx = m.x;
  const AxisShift& sy = m.y;
  if (!moving_) {
    // A still camera: nothing has moved until the picture moved by whole bins in several of
    // the last frames (one frame's vote can be a large foreground's). The motion is followed
    // all along, and reported from then on.
    recent_moves_.push_back((sx.ok && sx.whole != 0) || (sy.ok && sy.whole != 0));
    if (recent_moves_.size() > static_cast<size_t>(params_.trigger_frames)) recent_moves_.pop_front();
    moving_ = std::count(recent_moves_.begin(), recent_moves_.end(), true) >= params_.trigger_moves;
  }
  // An axis not found against the reference (too far from it, or something crossed it): the
  // previous frame's shift and the step from it; else the previous frame's shift.
  PictureMotion step;
  if (!sx.ok || !sy.ok) step = MeasurePictureMotion(previous_, now, params_);
  // An axis no tile has texture along (a door's plain panels) says nothing: its shift is kept
  // and not counted as a failure.
  auto axis = [&](const AxisShift& s, double ref, const AxisShift& from_previous, double* d) {
    if (s.ok) {
      *d = ref + s.bins * bin;
      return true;
    }
    if (from_previous.ok) *d += from_previous.bins * bin;
    return s.told == 0;
  };
  const bool ok_x = axis(sx, ref_dx_, step.x, &dx_);
  const bool ok_y = axis(sy, ref_dy_, step.y, &dy_);
  if (moving_) max_offset_ = std::max(max_offset_, std::hypot(dx_, dy_));
  // A new reference once the picture has moved far from it (while both axes are known), or
  // once it has not been found for several frames (the scene changed).
  failures_ = ok_x && ok_y ? 0 : failures_ + 1;
  if (failures_ > 0 && moving_) ++unmeasured_;
  const bool far = std::max(sx.ok ? std::abs(sx.whole) : 0, sy.ok ? std::abs(sy.whole) : 0) >= params_.rekey_bins;
  if ((ok_x && ok_y && far) || failures_ >= params_.rekey_after_failures) {
    reference_ = now, ref_dx_ = dx_, ref_dy_ = dy_;
    failures_ = 0;
  }
  previous_ = std::move(now);
}

}  // namespace bouncefit
