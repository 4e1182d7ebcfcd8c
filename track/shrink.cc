#include "track/shrink.h"

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <vector>

#include <stdexcept>

namespace bouncefit {

void ShrinkByBlocks(const cv::Mat& src, cv::Mat* dst, int factor) {
  if (factor < 1 || (factor & (factor - 1)) != 0)
    throw std::invalid_argument("ShrinkByBlocks: factor must be a power of two");
  const cv::Size target(src.cols / factor, src.rows / factor);
  if (factor == 1) {
    src.copyTo(*dst);
    return;
  }
  cv::Mat a, b;
  const cv::Mat* from = &src;
  for (int f = factor; f > 1; f /= 2) {
    // The last step lands on the exact target size (the block grid of the original).
    cv::Mat& to = f == 2 ? *dst : (from == &a ? b : a);
    const cv::Size next = f == 2 ? target : cv::Size(from->cols / 2, from->rows / 2);
    cv::resize(*from, to, next, 0, 0, cv::INTER_LINEAR);
    from = &to;
  }
}

namespace {

struct AreaTap {
  int s;        // source pixel
  float alpha;  // its weight
};

// The source pixels each output pixel of an n -> m area shrink covers, with weights, in the
// order OpenCV's resize lists them (imgproc's area table: the cell's cut first pixel, its
// whole ones, its cut last one; weights of the cell width, float). *first gets m + 1 offsets.
std::vector<AreaTap> AreaTaps(int n, int m, std::vector<int>* first) {
  const double scale = 1.0 / (static_cast<double>(m) / n);  // as cv::resize derives it
  std::vector<AreaTap> taps;
  first->assign(1, 0);
  for (int d = 0; d < m; ++d) {
    const double f1 = d * scale, f2 = f1 + scale;
    const double cell = std::min(scale, n - f1);
    const int s2 = std::min(static_cast<int>(std::floor(f2)), n - 1);
    const int s1 = std::min(static_cast<int>(std::ceil(f1)), s2);
    if (s1 - f1 > 1e-3) taps.push_back({s1 - 1, static_cast<float>((s1 - f1) / cell)});
    for (int s = s1; s < s2; ++s) taps.push_back({s, static_cast<float>(1.0 / cell)});
    if (f2 - s2 > 1e-3) taps.push_back({s2, static_cast<float>(std::min(std::min(f2 - s2, 1.0), cell) / cell)});
    first->push_back(static_cast<int>(taps.size()));
  }
  return taps;
}

// One source row's horizontal sums, 3 floats an output pixel: pixel x alpha over the pixel's
// taps in order, from 0 (OpenCV's buffer). The row is made floats first (`floats`: 3 cols + 1,
// the last a pad), so that a tap is one 4-float load, a product and a sum: all three channels
// in one vector (the fourth lane, the next pixel's first value, dropped), two output pixels
// side by side (their sums do not wait on each other).
void RowSums(const uint8_t* row, int cols, const std::vector<AreaTap>& taps,
             const std::vector<int>& first, float* floats, float* out) {
  const int m = static_cast<int>(first.size()) - 1;
  for (int i = 0; i < 3 * cols; ++i) floats[i] = row[i];
  floats[3 * cols] = 0;
  auto tap = [&](int k) {
    const AreaTap& t = taps[static_cast<size_t>(k)];
    return cv::v_load(floats + 3 * t.s) * cv::v_setall_f32(t.alpha);
  };
  int d = 0;
  for (; d + 1 < m; d += 2) {
    int k0 = first[static_cast<size_t>(d)], k1 = first[static_cast<size_t>(d) + 1];
    const int e0 = k1, e1 = first[static_cast<size_t>(d) + 2];
    cv::v_float32x4 a0 = cv::v_setzero_f32(), a1 = cv::v_setzero_f32();
    for (; k0 < e0 && k1 < e1; ++k0, ++k1) a0 = a0 + tap(k0), a1 = a1 + tap(k1);
    for (; k0 < e0; ++k0) a0 = a0 + tap(k0);
    for (; k1 < e1; ++k1) a1 = a1 + tap(k1);
    float l[8];
    cv::v_store(l, a0);
    cv::v_store(l + 4, a1);
    out[3 * d] = l[0], out[3 * d + 1] = l[1], out[3 * d + 2] = l[2];
    out[3 * d + 3] = l[4], out[3 * d + 4] = l[5], out[3 * d + 5] = l[6];
  }
  for (; d < m; ++d) {
    cv::v_float32x4 a = cv::v_setzero_f32();
    for (int k = first[static_cast<size_t>(d)]; k < first[static_cast<size_t>(d) + 1]; ++k) a = a + tap(k);
    float l[4];
    cv::v_store(l, a);
    out[3 * d] = l[0], out[3 * d + 1] = l[1], out[3 * d + 2] = l[2];
  }
}

// Which computes an 8-bit BGR shrink: OpenCV itself (not BGR, not shrinking: its own errors
// and copies; 2 x 2, its own vector path, which rounds its own way), the whole factors' block
// sums here (cv::resize's area-fast case: factors within DBL_EPSILON of integers, as it
// derives them; 1/(1/49) is not, and goes the fractional way there too), or the fractional
// taps here (its general area loop).
enum class AreaShrink { kOpenCv, kWholeFactors, kFractional };

AreaShrink HowToShrink(const cv::Mat& src, cv::Size size, int* kx, int* ky) {
  if (src.type() != CV_8UC3 || src.empty() || size.width < 1 || size.height < 1 ||
      size.width > src.cols || size.height > src.rows)
    return AreaShrink::kOpenCv;
  const double sx = 1.0 / (static_cast<double>(size.width) / src.cols);
  const double sy = 1.0 / (static_cast<double>(size.height) / src.rows);
  *kx = static_cast<int>(std::lround(sx)), *ky = static_cast<int>(std::lround(sy));
  if (!(std::abs(sx - *kx) < DBL_EPSILON && std::abs(sy - *ky) < DBL_EPSILON)) return AreaShrink::kFractional;
  const bool opencv_vector_path = *kx == 2 && *ky == 2;
  return opencv_vector_path || *kx * *ky == 1 || *ky > 257 ? AreaShrink::kOpenCv  // > 257: a row sum outgrows 16 bits
                                                          : AreaShrink::kWholeFactors;
}

// Whole factors (src exactly kx x ky blocks): the blocks' rows summed 16 bytes a step, then
// each block's integer sum times 1/area in float, rounded by cv::saturate_cast: OpenCV's area
// loop's arithmetic (its block sum through an offset table, 1.7-2.5 times slower on a 1080p frame).
void ShrinkByWholeFactor(const cv::Mat& src, cv::Mat* dst, cv::Size size, int kx, int ky) {
  dst->create(size, CV_8UC3);
  const float scale = 1.f / static_cast<float>(kx * ky);
  const int n = 3 * src.cols;
  std::vector<uint16_t> sums(static_cast<size_t>(n));
  std::vector<const uint8_t*> rows(static_cast<size_t>(ky));
  for (int d = 0; d < size.height; ++d) {
    for (int k = 0; k < ky; ++k) rows[static_cast<size_t>(k)] = src.ptr<uint8_t>(d * ky + k);
    int i = 0;
#if CV_SIMD128
    for (; i + 16 <= n; i += 16) {
      cv::v_uint16x8 lo, hi;
      cv::v_expand(cv::v_load(rows[0] + i), lo, hi);
      for (int k = 1; k < ky; ++k) {
        cv::v_uint16x8 a, b;
        cv::v_expand(cv::v_load(rows[static_cast<size_t>(k)] + i), a, b);
        lo = lo + a, hi = hi + b;
      }
      cv::v_store(sums.data() + i, lo);
      cv::v_store(sums.data() + i + 8, hi);
    }
#endif
    for (; i < n; ++i) {
      int sum = 0;
      for (int k = 0; k < ky; ++k) sum += rows[static_cast<size_t>(k)][i];
      sums[static_cast<size_t>(i)] = static_cast<uint16_t>(sum);
    }
    uint8_t* out = dst->ptr<uint8_t>(d);
    for (int x = 0; x < size.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const uint16_t* p = sums.data() + 3 * x * kx + c;
        int sum = 0;
        for (int j = 0; j < kx; ++j) sum += p[3 * j];
        out[3 * x + c] = cv::saturate_cast<uint8_t>(static_cast<float>(sum) * scale);
      }
  }
}

}  // namespace

void ShrinkByArea(const cv::Mat& src, cv::Mat* dst, cv::Size size) {
  int kx = 0, ky = 0;
  switch (HowToShrink(src, size, &kx, &ky)) {
    case AreaShrink::kOpenCv:
      cv::resize(src, *dst, size, 0, 0, cv::INTER_AREA);
      return;
    case AreaShrink::kWholeFactors:
      ShrinkByWholeFactor(src, dst, size, kx, ky);
      return;
    case AreaShrink::kFractional:
      break;
  }
  std::vector<int> xfirst, yfirst;
  const std::vector<AreaTap> xtaps = AreaTaps(src.cols, size.width, &xfirst);
  const std::vector<AreaTap> ytaps = AreaTaps(src.rows, size.height, &yfirst);
  dst->create(size, CV_8UC3);
  const size_t n = 3 * static_cast<size_t>(size.width);
  std::vector<float> row(n), sum(n), floats(3 * static_cast<size_t>(src.cols) + 1);
  int row_of = -1;  // the source row `row` holds (a row two output rows share is summed once)
  for (int d = 0; d < size.height; ++d) {
    for (int k = yfirst[static_cast<size_t>(d)]; k < yfirst[static_cast<size_t>(d) + 1]; ++k) {
      const AreaTap& t = ytaps[static_cast<size_t>(k)];
      if (t.s != row_of) RowSums(src.ptr<uint8_t>(t.s), src.cols, xtaps, xfirst, floats.data(), row.data()), row_of = t.s;
      // beta x row, then + beta x row: OpenCV's vertical sum (its first 0 + x is x).
      if (k == yfirst[static_cast<size_t>(d)])
        for (size_t i = 0; i < n; ++i) sum[i] = t.alpha * row[i];
      else
        for (size_t i = 0; i < n; ++i) sum[i] += t.alpha * row[i];
    }
    uint8_t* out = dst->ptr<uint8_t>(d);
    for (size_t i = 0; i < n; ++i) out[i] = cv::saturate_cast<uint8_t>(sum[i]);
  }
}

}  // namespace bouncefit
