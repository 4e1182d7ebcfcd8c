#include "track/ycc_planes.h"

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {

namespace {

constexpr float kKr = 0.299f, kKg = 0.587f, kKb = 0.114f;
constexpr float kCbScale = 0.5f / (1.0f - kKb);  // 0.564
constexpr float kCrScale = 0.5f / (1.0f - kKr);  // 0.713
// Limited-range (video) YUYV bytes to full range.
constexpr float kYLimScale = 255.0f / 219.0f;
constexpr float kCLimScale = 255.0f / 224.0f;

}  // namespace

void CheckFrameFormat(const Frame& frame) {
  if (frame.image.empty()) throw std::invalid_argument("empty frame");
  if (frame.format == PixelFormat::kBgr24 && frame.image.type() != CV_8UC3)
    throw std::invalid_argument("BGR frame must be CV_8UC3");
  if (frame.format == PixelFormat::kYuyv &&
      (frame.image.type() != CV_8UC2 || frame.image.cols % 2 != 0))
    throw std::invalid_argument("YUYV frame must be CV_8UC2 with an even width");
}

namespace {

#if CV_SIMD128
// 16 bytes as four vectors of four floats, in order.
void ToFloats(const cv::v_uint8x16& x, cv::v_float32x4 out[4]) {
  cv::v_uint16x8 lo, hi;
  cv::v_expand(x, lo, hi);
  cv::v_uint32x4 a, b, c, d;
  cv::v_expand(lo, a, b);
  cv::v_expand(hi, c, d);
  out[0] = cv::v_cvt_f32(cv::v_reinterpret_as_s32(a));
  out[1] = cv::v_cvt_f32(cv::v_reinterpret_as_s32(b));
  out[2] = cv::v_cvt_f32(cv::v_reinterpret_as_s32(c));
  out[3] = cv::v_cvt_f32(cv::v_reinterpret_as_s32(d));
}

// Four pixels' planes from their B, G, R: the formula below, the same float operations.
inline void StoreYcc(const cv::v_float32x4& b, const cv::v_float32x4& g, const cv::v_float32x4& r,
                     float* py, float* pu, float* pv) {
  const cv::v_float32x4 yy = cv::v_setall_f32(kKr) * r + cv::v_setall_f32(kKg) * g + cv::v_setall_f32(kKb) * b;
  cv::v_store(py, yy);
  cv::v_store(pu, (b - yy) * cv::v_setall_f32(kCbScale));
  cv::v_store(pv, (r - yy) * cv::v_setall_f32(kCrScale));
}

// One channel of 16 x 2 source pixels (rows x0, x1) as 8 means of 2x2 blocks: the integer
// sums (exact in 16 bits), then x norm as floats, into out[0] (blocks 0-3) and out[1] (4-7).
inline void BlockMeans(const cv::v_uint8x16& x0, const cv::v_uint8x16& x1, float norm, cv::v_float32x4 out[2]) {
  cv::v_uint16x8 a_lo, a_hi, c_lo, c_hi;
  cv::v_expand(x0, a_lo, a_hi);
  cv::v_expand(x1, c_lo, c_hi);
  // Column sums; a 32-bit lane holds two neighbours' (little-endian), summed as its halves.
  const cv::v_uint32x4 lo = cv::v_reinterpret_as_u32(a_lo + c_lo), hi = cv::v_reinterpret_as_u32(a_hi + c_hi);
  const cv::v_uint32x4 low16 = cv::v_setall_u32(0xFFFF);
  out[0] = cv::v_cvt_f32(cv::v_reinterpret_as_s32((lo & low16) + (lo >> 16))) * cv::v_setall_f32(norm);
  out[1] = cv::v_cvt_f32(cv::v_reinterpret_as_s32((hi & low16) + (hi >> 16))) * cv::v_setall_f32(norm);
}
#endif

void ExtractBgr(const cv::Mat& img, cv::Rect r, int step, YccPlanes* out) {
  const int w = r.width / step, h = r.height / step;
  const float norm = 1.0f / static_cast<float>(step * step);
  for (int j = 0; j < h; ++j) {
    float* py = out->y.ptr<float>(j);
    float* pu = out->u.ptr<float>(j);
    float* pv = out->v.ptr<float>(j);
    if (step == 1) {
      const uint8_t* s = img.ptr<uint8_t>(r.y + j) + 3 * r.x;
      int i = 0;
#if CV_SIMD128
      // 16 pixels a step with OpenCV's universal intrinsics (the compiler left this loop
      // scalar: a quarter of a close-up ball's tracking, in instructions). The same products
      // and sums in the same order as below: the same floats.
      for (; i + 16 <= w; i += 16, s += 48) {
        cv::v_uint8x16 b8, g8, r8;
        cv::v_load_deinterleave(s, b8, g8, r8);
        cv::v_float32x4 b[4], g[4], rr[4];
        ToFloats(b8, b), ToFloats(g8, g), ToFloats(r8, rr);
        for (int q = 0; q < 4; ++q) StoreYcc(b[q], g[q], rr[q], py + i + 4 * q, pu + i + 4 * q, pv + i + 4 * q);
      }
#endif
      for (; i < w; ++i, s += 3) {
        const float b = s[0], g = s[1], rr = s[2];
        const float yy = kKr * rr + kKg * g + kKb * b;
        py[i] = yy;
        pu[i] = (b - yy) * kCbScale;
        pv[i] = (rr - yy) * kCrScale;
      }
    } else {
      const uint8_t* s0 = img.ptr<uint8_t>(r.y + 2 * j) + 3 * r.x;
      const uint8_t* s1 = img.ptr<uint8_t>(r.y + 2 * j + 1) + 3 * r.x;
      int i = 0;
#if CV_SIMD128
      // 16 output pixels (32 x 2 source pixels) a step: the integer block sums, then the
      // same float product and conversion as below.
      for (; i + 16 <= w; i += 16, s0 += 96, s1 += 96) {
        cv::v_float32x4 b[4], g[4], rr[4];
        for (int half = 0; half < 2; ++half) {
          cv::v_uint8x16 b0, g0, r0, b1, g1, r1;
          cv::v_load_deinterleave(s0 + 48 * half, b0, g0, r0);
          cv::v_load_deinterleave(s1 + 48 * half, b1, g1, r1);
          BlockMeans(b0, b1, norm, b + 2 * half);
          BlockMeans(g0, g1, norm, g + 2 * half);
          BlockMeans(r0, r1, norm, rr + 2 * half);
        }
        for (int q = 0; q < 4; ++q) StoreYcc(b[q], g[q], rr[q], py + i + 4 * q, pu + i + 4 * q, pv + i + 4 * q);
      }
#endif
      for (; i < w; ++i, s0 += 6, s1 += 6) {
        const float b = (s0[0] + s0[3] + s1[0] + s1[3]) * norm;
        const float g = (s0[1] + s0[4] + s1[1] + s1[4]) * norm;
        const float rr = (s0[2] + s0[5] + s1[2] + s1[5]) * norm;
        const float yy = kKr * rr + kKg * g + kKb * b;
        py[i] = yy;
        pu[i] = (b - yy) * kCbScale;
        pv[i] = (rr - yy) * kCrScale;
      }
    }
  }
}

// YUYV: bytes Y0 U Y1 V per pixel pair; the pair's chroma sits between its two pixels.
void ExtractYuyv(const cv::Mat& img, cv::Rect r, int step, YccPlanes* out) {
  const int w = r.width / step, h = r.height / step;
  const int pairs = img.cols / 2;
  for (int j = 0; j < h; ++j) {
    float* py = out->y.ptr<float>(j);
    float* pu = out->u.ptr<float>(j);
    float* pv = out->v.ptr<float>(j);
    if (step == 1) {
      const uint8_t* row = img.ptr<uint8_t>(r.y + j);
      for (int i = 0; i < w; ++i) {
        const int x = r.x + i;
        const int k = x >> 1;
        // Chroma of pair k is centred at 2k+0.5: interpolate 3:1 with the nearer neighbour.
        const int kn = (x & 1) ? std::min(k + 1, pairs - 1) : std::max(k - 1, 0);
        const uint8_t* a = row + 4 * k;
        const uint8_t* n = row + 4 * kn;
        py[i] = (row[2 * x] - 16.0f) * kYLimScale;
        pu[i] = (0.75f * a[1] + 0.25f * n[1] - 128.0f) * kCLimScale;
        pv[i] = (0.75f * a[3] + 0.25f * n[3] - 128.0f) * kCLimScale;
      }
    } else {
      // 2x2 average: one pixel pair per output pixel when x is even.
      const uint8_t* r0 = img.ptr<uint8_t>(r.y + 2 * j);
      const uint8_t* r1 = img.ptr<uint8_t>(r.y + 2 * j + 1);
      for (int i = 0; i < w; ++i) {
        const int x = r.x + 2 * i;  // rect.x is even for step 2 (see ExtractYcc)
        const uint8_t* a = r0 + 2 * x;
        const uint8_t* b = r1 + 2 * x;
        py[i] = ((a[0] + a[2] + b[0] + b[2]) * 0.25f - 16.0f) * kYLimScale;
        pu[i] = ((a[1] + b[1]) * 0.5f - 128.0f) * kCLimScale;
        pv[i] = ((a[3] + b[3]) * 0.5f - 128.0f) * kCLimScale;
      }
    }
  }
}

}  // namespace

cv::Size FramePixelSize(const Frame& frame) { return frame.image.size(); }

void ExtractYcc(const Frame& frame, cv::Rect rect, int step, double blur_sigma_px,
                YccPlanes* out) {
  CheckFrameFormat(frame);
  if (step != 1 && step != 2) throw std::invalid_argument("decimation step must be 1 or 2");
  rect &= cv::Rect(0, 0, frame.image.cols, frame.image.rows);
  if (step == 2) {
    // Even origin and size, so 2x2 cells line up with YUYV pairs.
    const int x0 = rect.x & ~1, y0 = rect.y & ~1;
    rect = cv::Rect(x0, y0, (rect.x + rect.width - x0) & ~1, (rect.y + rect.height - y0) & ~1);
  }
  out->rect = rect;
  out->step = step;
  const int w = rect.width / step, h = rect.height / step;
  out->y.create(h, w, CV_32F);
  out->u.create(h, w, CV_32F);
  out->v.create(h, w, CV_32F);
  if (w <= 0 || h <= 0) return;
  const int k = blur_sigma_px > 0 ? 2 * static_cast<int>(std::ceil(2.0 * blur_sigma_px)) + 1 : 0;
  if (frame.format == PixelFormat::kBgr24) {
    if (k > 0 && step == 1) {
      // BGR -> YCbCr is linear: blur the 8-bit pixels first (neighbours outside the rect
      // included), then convert. A view of the frame goes through OpenCV's float filter, not
      // its fixed-point one (that needs BORDER_ISOLATED): on a ball's window the fixed-point
      // filter costs as many instructions and rounds otherwise, so the tracks would change.
      thread_local cv::Mat blurred;
      cv::GaussianBlur(frame.image(rect), blurred, cv::Size(k, k), blur_sigma_px, blur_sigma_px,
                       cv::BORDER_REPLICATE);
      ExtractBgr(blurred, cv::Rect(0, 0, rect.width, rect.height), 1, out);
      return;
    }
    ExtractBgr(frame.image, rect, step, out);
  } else {
    ExtractYuyv(frame.image, rect, step, out);
  }
  if (k > 0) {
    const cv::Size ks(k, k);
    cv::GaussianBlur(out->y, out->y, ks, blur_sigma_px, blur_sigma_px, cv::BORDER_REPLICATE);
    cv::GaussianBlur(out->u, out->u, ks, blur_sigma_px, blur_sigma_px, cv::BORDER_REPLICATE);
    cv::GaussianBlur(out->v, out->v, ks, blur_sigma_px, blur_sigma_px, cv::BORDER_REPLICATE);
  }
}

void BgrToYuv(double b, double g, double r, double* y, double* u, double* v) {
  *y = kKr * r + kKg * g + kKb * b;
  *u = (b - *y) * kCbScale;
  *v = (r - *y) * kCrScale;
}

void YuvToBgr(double y, double u, double v, double* b, double* g, double* r) {
  *b = std::clamp(y + u / kCbScale, 0.0, 255.0);
  *r = std::clamp(y + v / kCrScale, 0.0, 255.0);
  const double rr = y + v / kCrScale, bb = y + u / kCbScale;
  *g = std::clamp((y - kKr * rr - kKb * bb) / kKg, 0.0, 255.0);
}

}  // namespace bouncefit
