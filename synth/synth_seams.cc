#include "synth/synth_seams.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace bouncefit {
namespace {

using Mat3 = std::array<double, 9>;  // row-major

Mat3 Multiply(const Mat3& a, const Mat3& b) {
  Mat3 m{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) m[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return m;
}

Mat3 Transposed(const Mat3& a) { return {a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]}; }

// Rotation by `angle` about the unit axis (x, y, z) (Rodrigues).
Mat3 Rotation(double x, double y, double z, double angle) {
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  return {c + t * x * x,     t * x * y - s * z, t * x * z + s * y,
          t * x * y + s * z, c + t * y * y,     t * y * z - s * x,
          t * x * z - s * y, t * y * z + s * x, c + t * z * z};
}

// How the pattern sits on the ball at spin 0 (not square to the camera: every panel's outline
// is curved), and the axis it spins about (mostly towards the camera: a ball spinning in the
// plane of its flight, tilted so that the panels change shape as it turns), camera axes.
const Mat3 kTilt = Multiply(Rotation(1, 0, 0, 0.6), Rotation(0, 1, 0, 0.45));
constexpr double kAxisX = 0.35, kAxisY = 0.25, kAxisZ = 0.9028;  // unit

// A basketball's rings: round the z axis at this height (radii).
constexpr double kRingZ = 0.72;
// A tennis ball's seam: z = kTennisBend (x^2 - y^2), reaching 51 degrees above and below the
// equator.
constexpr double kTennisBend = 2.0;

}  // namespace

SeamPattern ParseSeamPattern(const std::string& name) {
  if (name == "none") return SeamPattern::kNone;
  if (name == "basketball") return SeamPattern::kBasketball;
  if (name == "tennis") return SeamPattern::kTennis;
  throw std::invalid_argument("seams must be none, basketball or tennis (got '" + name + "')");
}

const char* SeamPatternName(SeamPattern pattern) {
  switch (pattern) {
    case SeamPattern::kBasketball: return "basketball";
    case SeamPattern::kTennis: return "tennis";
    default: return "none";
  }
}

BallSeams::BallSeams(SeamPattern pattern, double width_share) : pattern_(pattern), half_width_(width_share) {
  Turn(0);
}

void BallSeams::Turn(double spin_rad) {
  // Camera point q = Spin Tilt p: p = Tilt^T Spin^T q.
  to_body_ = Multiply(Transposed(kTilt), Transposed(Rotation(kAxisX, kAxisY, kAxisZ, spin_rad)));
}

double BallSeams::Distance(const std::array<double, 3>& p) const {
  const double x = p[0], y = p[1], z = p[2];
  if (pattern_ == SeamPattern::kBasketball) {
    const double ring = std::abs(std::abs(z) - kRingZ) / std::sqrt(1 - kRingZ * kRingZ);
    return std::min({std::abs(x), std::abs(y), ring});
  }
  // The level set f = 0 of f = z - k (x^2 - y^2): |f| over its gradient along the surface.
  const double f = z - kTennisBend * (x * x - y * y);
  const double gx = -2 * kTennisBend * x, gy = 2 * kTennisBend * y, gz = 1;
  const double along = gx * x + gy * y + gz * z;
  const double tx = gx - along * x, ty = gy - along * y, tz = gz - along * z;
  return std::abs(f) / std::max(1e-6, std::sqrt(tx * tx + ty * ty + tz * tz));
}

double BallSeams::Coverage(double u, double v, double radius_px) const {
  if (pattern_ == SeamPattern::kNone) return 0;
  // The visible surface point: z towards the camera.
  const double w = std::sqrt(std::max(0.0, 1 - u * u - v * v));
  const Mat3& m = to_body_;
  const std::array<double, 3> p = {m[0] * u + m[1] * v + m[2] * w, m[3] * u + m[4] * v + m[5] * w,
                                   m[6] * u + m[7] * v + m[8] * w};
  const double d = Distance(p);
  return std::clamp(0.5 + (half_width_ - d) * radius_px, 0.0, 1.0);
}

}  // namespace bouncefit
