#include "track/change_map.h"

#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <array>
#include <cstdlib>

namespace bouncefit {

int MedianOfEvery4th(const cv::Mat& d) {
  std::array<int, 256> count{};
  int n = 0;
  for (int j = 0; j < d.rows; j += 4) {
    const uint8_t* p = d.ptr<uint8_t>(j);
    for (int i = 0; i < d.cols; i += 4, ++n) ++count[p[i]];
  }
  int below = 0;
  for (int v = 0; v < 256; ++v)
    if ((below += count[static_cast<size_t>(v)]) > n / 2) return v;
  return 0;
}

void ChangeMap(const cv::Mat& a, const cv::Mat& b, cv::Mat& d) {
  CV_Assert(a.type() == CV_8UC3 && b.type() == CV_8UC3 && a.size() == b.size());
  d.create(a.size(), CV_8U);
  for (int j = 0; j < a.rows; ++j) {
    const uint8_t* pa = a.ptr<uint8_t>(j);
    const uint8_t* pb = b.ptr<uint8_t>(j);
    uint8_t* q = d.ptr<uint8_t>(j);
    int i = 0;
#if CV_SIMD128
    for (; i + 16 <= a.cols; i += 16) {
      cv::v_uint8x16 a0, a1, a2, b0, b1, b2;
      cv::v_load_deinterleave(pa + 3 * i, a0, a1, a2);
      cv::v_load_deinterleave(pb + 3 * i, b0, b1, b2);
      cv::v_uint16x8 lo0, hi0, lo1, hi1, lo2, hi2;
      cv::v_expand(cv::v_absdiff(a0, b0), lo0, hi0);
      cv::v_expand(cv::v_absdiff(a1, b1), lo1, hi1);
      cv::v_expand(cv::v_absdiff(a2, b2), lo2, hi2);
      cv::v_store(q + i, cv::v_pack(lo0 + lo1 + lo2, hi0 + hi1 + hi2));
    }
#endif
    for (; i < a.cols; ++i) {
      const uint8_t* x = pa + 3 * i;
      const uint8_t* y = pb + 3 * i;
      q[i] = static_cast<uint8_t>(std::min(255, std::abs(x[0] - y[0]) + std::abs(x[1] - y[1]) + std::abs(x[2] - y[2])));
    }
  }
}

namespace {

// out = the max (dilate) or min (erode) of each pixel of `in` and its four neighbours inside.
template <bool kMax>
void CrossFilter(const cv::Mat& in, cv::Mat& out) {
  const int w = in.cols, h = in.rows;
  out.create(in.size(), CV_8U);
  auto pick = [](uint8_t a, uint8_t b) { return kMax ? std::max(a, b) : std::min(a, b); };
  for (int y = 0; y < h; ++y) {
    const uint8_t* c = in.ptr<uint8_t>(y);
    const uint8_t* up = y > 0 ? in.ptr<uint8_t>(y - 1) : c;  // the row itself: no effect
    const uint8_t* down = y + 1 < h ? in.ptr<uint8_t>(y + 1) : c;
    uint8_t* o = out.ptr<uint8_t>(y);
    auto one = [&](int x) {
      uint8_t v = pick(c[x], pick(up[x], down[x]));
      if (x > 0) v = pick(v, c[x - 1]);
      if (x + 1 < w) v = pick(v, c[x + 1]);
      o[x] = v;
    };
    if (w > 0) one(0);
    int x = 1;
#if CV_SIMD128
    auto vpick = [](const cv::v_uint8x16& a, const cv::v_uint8x16& b) { return kMax ? cv::v_max(a, b) : cv::v_min(a, b); };
    for (; x + 17 <= w; x += 16) {
      const cv::v_uint8x16 v = vpick(vpick(cv::v_load(c + x - 1), cv::v_load(c + x + 1)),
                                     vpick(cv::v_load(c + x), vpick(cv::v_load(up + x), cv::v_load(down + x))));
      cv::v_store(o + x, v);
    }
#endif
    for (; x < w; ++x) one(x);
  }
}

}  // namespace

void CloseByCross(cv::Mat& mask) {
  CV_Assert(mask.type() == CV_8U);
  thread_local cv::Mat dilated;
  CrossFilter<true>(mask, dilated);
  CrossFilter<false>(dilated, mask);
}

}  // namespace bouncefit
