#include "track/picture_shift.h"

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
  std::vector<double> cost;
  double best = std::numeric_limits<double>::max();
  int best_d = 0;
  for (int d = -max_shift; d <= max_shift; ++d) {
    double s = 0;
    int m = 0;
    for (int i = std::max(0, -d); i < std::min(n, n - d); ++i) s += std::abs(a[i] - b[i + d]), ++m;
    cost.push_back(m > 0 ? s / m : 1e9);
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
  PictureProfiles out;
  out.size = ycc.size();
  const int t = params.tiles;
  cv::Mat luma;
  cv::extractChannel(ycc, luma, 0);
  for (int ty = 0; ty < t; ++ty)
    for (int tx = 0; tx < t; ++tx) {
      const cv::Rect r(tx * ycc.cols / t, ty * ycc.rows / t, ycc.cols / t, ycc.rows / t);
      // Integer sums over the luma plane on its own: exact, and vectorised (a float sum over
      // every third byte is a chain of dependent adds).
      std::vector<int> col_sums(std::max(0, r.width), 0);
      std::vector<float> rows(std::max(0, r.height), 0.0f);
      for (int j = 0; j < r.height; ++j) {
        const uint8_t* q = luma.ptr<uint8_t>(r.y + j) + r.x;
        int sum = 0;
        for (int i = 0; i < r.width; ++i) col_sums[i] += q[i], sum += q[i];
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
