#include "track/picture_shift.h"

#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

namespace bouncefit {
namespace {

constexpr double kSharpness = 0.5;  // the best shift's mismatch under this share of the median

void RemoveMean(std::vector<float>& p, float n) {
  float mean = 0;
  for (float& v : p) v /= n, mean += v;
  mean /= static_cast<float>(p.size());
  for (float& v : p) v -= mean;
}

double Texture(const std::vector<float>& p) {
  double s = 0;
  for (size_t i = 1; i < p.size(); ++i) s += std::abs(p[i] - p[i - 1]);
  return p.size() > 1 ? s / static_cast<double>(p.size() - 1) : 0;
}

// The shift d of `b` against `a` (b[i + d] ~ a[i]) with the least mean absolute difference
// over the overlap. *ok: the profiles have texture to tell it by, and the least is inside
// the search (one at its edge is no minimum found).
int BestShift(const std::vector<float>& a, const std::vector<float>& b, int max_shift,
              double min_texture, bool* ok) {
  *ok = false;
  if (a.size() != b.size() || Texture(a) < min_texture || Texture(b) < min_texture) return 0;
  const int n = static_cast<int>(a.size());
  // Every shift's sum at once, each still added up in the order of i: the same doubles as
  // one shift at a time, but 2 max_shift + 1 independent sums instead of one chain of adds.
  const int shifts = 2 * max_shift + 1;
  std::vector<double> sums(shifts, 0.0);
  auto add_row = [&](int i, int k0, int k1) {  // shifts k0..k1-1 (d = k - max_shift) at a[i]
    const float ai = a[i];
    for (int k = k0; k < k1; ++k) sums[k] += std::abs(ai - b[i + k - max_shift]);
  };
  // Shift d has b[i + d] in [0, n): k in [max_shift - i, n + max_shift - i); all of them in
  // the middle of the profile.
  const int mid0 = std::min(max_shift, n), mid1 = std::max(mid0, n - max_shift);
  for (int i = 0; i < mid0; ++i) add_row(i, max_shift - i, std::min(shifts, n + max_shift - i));
  for (int i = mid0; i < mid1; ++i) add_row(i, 0, shifts);
  for (int i = mid1; i < n; ++i) add_row(i, std::max(0, max_shift - i), n + max_shift - i);
  std::vector<double> cost;
  double best = std::numeric_limits<double>::max();
  int best_d = 0;
  for (int d = -max_shift; d <= max_shift; ++d) {
    const int m = n - std::abs(d);
    cost.push_back(m > 0 ? sums[d + max_shift] / m : 1e9);
    if (cost.back() < best) best = cost.back(), best_d = d;
  }
  // A minimum that stands out: well under the typical mismatch of the shifts searched (a
  // blank tile matches about as well at every shift).
  std::nth_element(cost.begin(), cost.begin() + cost.size() / 2, cost.end());
  *ok = std::abs(best_d) < max_shift && best < kSharpness * cost[cost.size() / 2];
  return best_d;
}

}  // namespace

PictureProfiles ProfilesOf(const cv::Mat& ycc, const PictureShiftParams& params) {
  CV_Assert(ycc.empty() || ycc.type() == CV_8UC3);
  PictureProfiles out;
  out.size = ycc.size();
  const int t = params.tiles;
  for (int ty = 0; ty < t; ++ty)
    for (int tx = 0; tx < t; ++tx) {
      const cv::Rect r(tx * ycc.cols / t, ty * ycc.rows / t, ycc.cols / t, ycc.rows / t);
      // Integer sums of the luma channel, read in place (a copy of the plane first cost as
      // much as the sums): exact, and each column's sum is independent of the next.
      std::vector<int> col_sums(std::max(0, r.width), 0);
      std::vector<float> rows(std::max(0, r.height), 0.0f);
      for (int j = 0; j < r.height; ++j) {
        const uint8_t* q = ycc.ptr<uint8_t>(r.y + j) + 3 * r.x;
        int* c = col_sums.data();
        int i = 0, sum = 0;
#if CV_SIMD128
        cv::v_uint32x4 row_sum = cv::v_setzero_u32();
        for (; i + 16 <= r.width; i += 16) {
          cv::v_uint8x16 y, cr, cb;
          cv::v_load_deinterleave(q + 3 * i, y, cr, cb);
          cv::v_uint16x8 y_lo, y_hi;
          cv::v_expand(y, y_lo, y_hi);
          cv::v_uint32x4 y0, y1, y2, y3;
          cv::v_expand(y_lo, y0, y1);
          cv::v_expand(y_hi, y2, y3);
          row_sum += (y0 + y1) + (y2 + y3);
          cv::v_store(c + i, cv::v_load(c + i) + cv::v_reinterpret_as_s32(y0));
          cv::v_store(c + i + 4, cv::v_load(c + i + 4) + cv::v_reinterpret_as_s32(y1));
          cv::v_store(c + i + 8, cv::v_load(c + i + 8) + cv::v_reinterpret_as_s32(y2));
          cv::v_store(c + i + 12, cv::v_load(c + i + 12) + cv::v_reinterpret_as_s32(y3));
        }
        sum = static_cast<int>(cv::v_reduce_sum(row_sum));
#endif
        for (; i < r.width; ++i) c[i] += q[3 * i], sum += q[3 * i];
        rows[j] = static_cast<float>(sum);
      }
      std::vector<float> cols(col_sums.begin(), col_sums.end());
      if (r.width > 0 && r.height > 0) {
        RemoveMean(cols, static_cast<float>(r.height));
        RemoveMean(rows, static_cast<float>(r.width));
      }
      out.columns.push_back(std::move(cols));
      out.rows.push_back(std::move(rows));
    }
  return out;
}

PictureShift MeasurePictureShift(const PictureProfiles& a, const PictureProfiles& b,
                                 const PictureShiftParams& params) {
  PictureShift out;
  if (a.size != b.size || a.columns.size() != b.columns.size()) return out;
  // Each axis on its own: a tile of vertical stripes tells dx and nothing of dy.
  auto agreed = [&](const std::vector<std::vector<float>>& pa,
                    const std::vector<std::vector<float>>& pb) {
    std::map<int, int> votes;
    int told = 0;
    for (size_t k = 0; k < pa.size(); ++k) {
      if (static_cast<int>(pa[k].size()) < 4 * params.max_shift_px) continue;
      bool ok = false;
      const int d = BestShift(pa[k], pb[k], params.max_shift_px, params.min_texture, &ok);
      if (ok) ++votes[d], ++told;
    }
    int best = 0, shift = 0;
    for (const auto& [d, n] : votes)
      if (n > best) best = n, shift = d;
    out.informative += told;
    out.agreeing += best;
    return best >= params.min_agreeing && best >= params.min_agreeing_share * told ? shift : 0;
  };
  out.dx = agreed(a.columns, b.columns);
  out.dy = agreed(a.rows, b.rows);
  return out;
}

}  // namespace bouncefit
