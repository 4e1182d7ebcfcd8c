#include "synth/synth_scene.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>

namespace bouncefit {
namespace {

// Light from the upper left, in front of the wall (scene axes: x right, y down, z to camera).
struct Light {
  double lx, ly, lz;  // unit direction to the light
  double hx, hy, hz;  // unit half vector between light and viewer (0, 0, 1)
  Light() {
    const double x = -0.45, y = -0.65, z = 0.62;
    const double n = std::sqrt(x * x + y * y + z * z);
    lx = x / n, ly = y / n, lz = z / n;
    const double hn = std::sqrt(lx * lx + ly * ly + (lz + 1) * (lz + 1));
    hx = lx / hn, hy = ly / hn, hz = (lz + 1) / hn;
  }
};
const Light kLight;

constexpr double kAmbient = 0.42;
constexpr double kDiffuse = 0.58;
constexpr double kSpecular = 0.22;

// Shaded colour of a sphere-like ball at normalised local position (u, v) (|.| <= 1 inside).
inline void ShadeSphere(double u, double v, const Bgr& color, float out[3]) {
  const double r2 = std::min(1.0, u * u + v * v);
  const double nz = std::sqrt(1.0 - r2);
  const double lambert = std::max(0.0, u * kLight.lx + v * kLight.ly + nz * kLight.lz);
  const double nh = std::max(0.0, u * kLight.hx + v * kLight.hy + nz * kLight.hz);
  double nh2 = nh * nh, nh4 = nh2 * nh2, nh8 = nh4 * nh4, nh16 = nh8 * nh8;
  const double spec = kSpecular * 255.0 * nh16 * nh8;  // Blinn-Phong, exponent 24
  const double k = kAmbient + kDiffuse * lambert;
  for (int c = 0; c < 3; ++c) out[c] = static_cast<float>(std::min(255.0, color[c] * k + spec));
}

inline double Clamp01(double x) { return x < 0 ? 0 : (x > 1 ? 1 : x); }

struct Box {
  int x0, y0, x1, y1;  // inclusive pixel range; empty when x1 < x0 or y1 < y0
  bool empty() const { return x1 < x0 || y1 < y0; }
  int w() const { return x1 - x0 + 1; }
  int h() const { return y1 - y0 + 1; }
};

Box ClipBox(double xmin, double ymin, double xmax, double ymax, int width, int height) {
  return {std::max(0, static_cast<int>(std::floor(xmin))),
          std::max(0, static_cast<int>(std::floor(ymin))),
          std::min(width - 1, static_cast<int>(std::ceil(xmax))),
          std::min(height - 1, static_cast<int>(std::ceil(ymax)))};
}

Box Union(const Box& a, const Box& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1),
          std::max(a.y1, b.y1)};
}

// The soft shadow of a ball whose bottom is h_px above the floor.
struct ShadowShape {
  double x, y, sx, sy, strength;
};

ShadowShape ShadowOf(const BallShape& b, double floor_y) {
  const double r = 0.5 * (b.a + b.b);
  const double h = std::max(0.0, floor_y - (b.y + b.b));
  const double sx = r * (1.0 + 0.5 * std::min(h / (4 * r), 2.0));
  const double sy = 0.3 * sx;
  return {b.x, floor_y + 0.5 * sy, sx, sy, 0.55 / (1.0 + h / (3 * r))};
}

// A well-mixed 32-bit hash of a cell and a salt, mapped to [0, 1).
double Hash01(int i, int j, unsigned salt) {
  uint32_t h = static_cast<uint32_t>(i) * 0x8da6b343u ^ static_cast<uint32_t>(j) * 0xd8163841u ^ salt * 0xcb1ab31fu;
  h ^= h >> 16, h *= 0x7feb352du, h ^= h >> 15, h *= 0x846ca68bu, h ^= h >> 16;
  return h / 4294967296.0;
}

}  // namespace

FloorPattern ParseFloorPattern(const std::string& name) {
  if (name == "plain") return FloorPattern::kPlain;
  if (name == "pebble") return FloorPattern::kPebble;
  throw std::invalid_argument("floor pattern must be plain or pebble (got '" + name + "')");
}

const char* FloorPatternName(FloorPattern pattern) {
  return pattern == FloorPattern::kPebble ? "pebble" : "plain";
}

Bgr SynthScene::FloorColor(cv::Point2d q) const {
  if (config_.floor_pattern != FloorPattern::kPebble) return config_.floor_bgr;
  // Pebbles: the cells of seeds jittered on a grid (squashed vertically, a floor seen at a
  // slant), each of its own grey or brown, in dark grout, darker towards its rim, with a
  // lighter or darker blotch and a fine grain.
  const double s = std::max(4.0, config_.pebble_px), squash = 1.6;
  const double u = q.x / s, v = q.y * squash / s;
  const int ci = static_cast<int>(std::floor(u)), cj = static_cast<int>(std::floor(v));
  double d1 = 1e9, d2 = 1e9;
  int bi = 0, bj = 0;
  double bx = 0, by = 0;
  for (int j = cj - 1; j <= cj + 1; ++j)
    for (int i = ci - 1; i <= ci + 1; ++i) {
      const double sx = i + 0.1 + 0.8 * Hash01(i, j, 1), sy = j + 0.1 + 0.8 * Hash01(i, j, 2);
      const double d = std::hypot(u - sx, v - sy);
      if (d < d1) d2 = d1, d1 = d, bi = i, bj = j, bx = sx, by = sy;
      else if (d < d2) d2 = d;
    }
  const double edge = d2 - d1;  // in pebble sizes: 0 on the border between two pebbles
  if (edge < 0.07) return {52, 56, 60};
  const double value = 70 + 140 * Hash01(bi, bj, 3), sat = 0.55 * Hash01(bi, bj, 4);
  const double warm = 0.3 + 0.5 * Hash01(bi, bj, 5);  // how far green follows red: brown to tan
  double k = 0.78 + 0.22 * std::min(1.0, edge / 0.3);
  const double spot_x = bx + 0.3 * (Hash01(bi, bj, 6) - 0.5), spot_y = by + 0.3 * (Hash01(bi, bj, 7) - 0.5);
  if (std::hypot(u - spot_x, v - spot_y) < 0.12 + 0.15 * Hash01(bi, bj, 8)) k *= Hash01(bi, bj, 9) < 0.5 ? 0.75 : 1.2;
  const double grain = 1 + 0.06 * (Hash01(static_cast<int>(std::floor(q.x)), static_cast<int>(std::floor(q.y)), 10) - 0.5);
  const double r = value * k * grain;
  return {std::min(255.0, r * (1 - sat)), std::min(255.0, r * (1 - sat * (1 - warm))), std::min(255.0, r)};
}

WallPattern ParseWallPattern(const std::string& name) {
  if (name == "plain") return WallPattern::kPlain;
  if (name == "brick") return WallPattern::kBrick;
  if (name == "poster") return WallPattern::kPoster;
  throw std::invalid_argument("wall pattern must be plain, brick or poster (got '" + name + "')");
}

const char* WallPatternName(WallPattern pattern) {
  switch (pattern) {
    case WallPattern::kBrick: return "brick";
    case WallPattern::kPoster: return "poster";
    default: return "plain";
  }
}

Bgr SynthScene::WallColor(cv::Point2d q) const {
  const Bgr& wall = config_.wall_bgr;
  if (config_.wall_pattern == WallPattern::kBrick) {
    // Courses of bricks 1/16 of the height tall, twice as long, every other course offset
    // by half a brick; 2 px light mortar; each brick a little lighter or darker.
    const double course = std::max(6.0, config_.height / 16.0), len = 2 * course;
    const int row = static_cast<int>(std::floor(q.y / course));
    const double xs = q.x + (row % 2 ? 0.5 * len : 0.0);
    const int col = static_cast<int>(std::floor(xs / len));
    const double in_y = q.y - row * course, in_x = xs - col * len;
    if (in_y < 2 || in_x < 2) return {178, 182, 186};
    const double k = 0.88 + 0.24 * ((static_cast<unsigned>(row * 7919 + col * 104729) % 97) / 96.0);
    return {std::min(255.0, wall[0] * k), std::min(255.0, wall[1] * k), std::min(255.0, wall[2] * k)};
  }
  for (auto it = poster_.rbegin(); it != poster_.rend(); ++it)
    if (it->first.contains(q)) return it->second;
  return wall;
}

SynthScene::SynthScene(const SynthSceneConfig& config) : config_(config) {
  const double th = config.roll_deg * std::numbers::pi / 180;
  cos_ = std::cos(th);
  sin_ = std::sin(th);
  center_ = {(config.width - 1) / 2.0, (config.height - 1) / 2.0};

  const double W = config.width, H = config.height, fy = config.floor_y_px;
  if (config.wall_pattern == WallPattern::kPoster) {
    // Forty overlapping patches of every hue, full saturation, fixed seed: the same wall
    // in every clip.
    std::mt19937 rng(20261123);
    std::uniform_real_distribution<double> u01(0, 1);
    for (int k = 0; k < 40; ++k) {
      const double w = (0.05 + 0.2 * u01(rng)) * W, h = (0.05 + 0.2 * u01(rng)) * fy;
      const cv::Rect2d rect(u01(rng) * (W - w), u01(rng) * (fy - h), w, h);
      const double hue = 6 * u01(rng), f = hue - std::floor(hue), v = 60 + 170 * u01(rng);
      const double rgb[6][3] = {{1, f, 0}, {1 - f, 1, 0}, {0, 1, f}, {0, 1 - f, 1}, {f, 0, 1}, {1, 0, 1 - f}};
      const double* c = rgb[static_cast<int>(hue) % 6];
      poster_.push_back({rect, {v * c[2], v * c[1], v * c[0]}});
    }
  }
  background_.create(config.height, config.width, CV_8UC3);
  for (int y = 0; y < config.height; ++y) {
    auto* row = background_.ptr<uchar>(y);
    for (int x = 0; x < config.width; ++x) {
      const cv::Point2d q = ToScene({static_cast<double>(x), static_cast<double>(y)});
      const double floor_cover = Clamp01(q.y - fy + 0.5);
      const double hx = (q.x - W / 2) / (W / 2);
      const double wall_k = (1.03 - 0.10 * std::clamp(q.y / H, 0.0, 1.0)) * (1 - 0.06 * hx * hx);
      const double floor_k = 0.92 + 0.12 * Clamp01((q.y - fy) / (0.2 * H));
      const Bgr wall = floor_cover < 1 ? WallColor(q) : Bgr{};
      const Bgr floor = floor_cover > 0 ? FloorColor(q) : Bgr{};
      for (int c = 0; c < 3; ++c) {
        const double v = wall[c] * wall_k * (1 - floor_cover) + floor[c] * floor_k * floor_cover;
        row[3 * x + c] = cv::saturate_cast<uchar>(v);
      }
    }
  }
  if (config.distractor) {
    const double r = config.distractor_radius_px;
    const std::vector<BallShape> d = {{config.distractor_x_px, fy - r, r, r}};
    const Bgr& b = config.ball_bgr;
    // Similar hue: a little darker, slightly shifted.
    const Bgr color = {std::clamp(b[0] * 0.85 + 15, 0.0, 255.0),
                       std::clamp(b[1] * 0.85 - 10, 0.0, 255.0),
                       std::clamp(b[2] * 0.92, 0.0, 255.0)};
    RenderShadow(d, &background_);
    RenderBall(d, color, false, &background_);
  }
}

cv::Point2d SynthScene::ToImage(cv::Point2d q) const {
  const double dx = q.x - center_.x, dy = q.y - center_.y;
  return {center_.x + cos_ * dx + sin_ * dy, center_.y - sin_ * dx + cos_ * dy};
}

cv::Point2d SynthScene::ToScene(cv::Point2d p) const {
  const double dx = p.x - center_.x, dy = p.y - center_.y;
  return {center_.x + cos_ * dx - sin_ * dy, center_.y + sin_ * dx + cos_ * dy};
}

bool SynthScene::FullyInView(const BallShape& b) const {
  const cv::Point2d c = ToImage({b.x, b.y});
  const double ex = std::sqrt(b.a * b.a * cos_ * cos_ + b.b * b.b * sin_ * sin_);
  const double ey = std::sqrt(b.a * b.a * sin_ * sin_ + b.b * b.b * cos_ * cos_);
  return c.x - ex >= -0.5 && c.y - ey >= -0.5 && c.x + ex <= config_.width - 0.5 &&
         c.y + ey <= config_.height - 0.5;
}

void SynthScene::Render(const std::vector<BallShape>& subs, cv::Mat* out, const HandShape* hand) const {
  background_.copyTo(*out);
  if (hand) RenderHand(*hand, out);
  if (subs.empty()) return;
  RenderShadow(subs, out);
  RenderBall(subs, config_.ball_bgr, true, out);
}

void SynthScene::RenderHand(const HandShape& h, cv::Mat* out) const {
  // The arm rises from the fist to the edge at a slant, its elbow out of the picture.
  const double run = std::abs(h.edge_x - h.x) + 2 * h.r;
  const cv::Point2d fist = ToImage({h.x, h.y});
  const cv::Point2d edge = ToImage({h.edge_x + (h.edge_x > h.x ? 2 * h.r : -2 * h.r), h.y - 0.4 * run});
  constexpr int kShift = 4;  // sub-pixel coordinates for the anti-aliased drawing
  auto fixed = [](cv::Point2d p) { return cv::Point(cv::saturate_cast<int>(p.x * (1 << kShift)),
                                                    cv::saturate_cast<int>(p.y * (1 << kShift))); };
  const cv::Scalar skin(105, 128, 178);
  cv::line(*out, fixed(fist), fixed(edge), skin, std::max(1, static_cast<int>(std::lround(1.4 * h.r))), cv::LINE_AA,
           kShift);
  cv::circle(*out, fixed(fist), static_cast<int>(std::lround(h.r * (1 << kShift))), skin, cv::FILLED, cv::LINE_AA,
             kShift);
}

void SynthScene::RenderShadow(const std::vector<BallShape>& subs, cv::Mat* out) const {
  std::vector<ShadowShape> shadows;
  Box box{0, 0, -1, -1};
  std::vector<Box> boxes;
  for (const auto& b : subs) {
    const double fy = std::isnan(b.floor_y) ? config_.floor_y_px : b.floor_y;
    const ShadowShape s = ShadowOf(b, fy);
    // Scene rectangle x +- 3 sx, y in [floor - 1, y + 3 sy], as an image box.
    double xmin = 1e300, ymin = 1e300, xmax = -1e300, ymax = -1e300;
    for (double qx : {s.x - 3 * s.sx, s.x + 3 * s.sx})
      for (double qy : {fy - 1, s.y + 3 * s.sy}) {
        const cv::Point2d p = ToImage({qx, qy});
        xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x);
        ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
      }
    boxes.push_back(ClipBox(xmin, ymin, xmax, ymax, config_.width, config_.height));
    box = Union(box, boxes.back());
    shadows.push_back(s);
  }
  if (box.empty()) return;
  std::vector<float> dark(static_cast<size_t>(box.w()) * box.h(), 0.f);
  const float inv_n = 1.0f / static_cast<float>(subs.size());
  for (size_t k = 0; k < shadows.size(); ++k) {
    const ShadowShape& s = shadows[k];
    const Box& b = boxes[k];
    if (b.empty()) continue;
    for (int y = b.y0; y <= b.y1; ++y) {
      float* drow = &dark[static_cast<size_t>(y - box.y0) * box.w()];
      for (int x = b.x0; x <= b.x1; ++x) {
        const cv::Point2d q = ToScene({static_cast<double>(x), static_cast<double>(y)});
        const double floor_cover = Clamp01(q.y - config_.floor_y_px + 0.5);
        if (floor_cover <= 0) continue;
        const double u = (q.x - s.x) / s.sx, v = (q.y - s.y) / s.sy;
        const double e = u * u + v * v;
        if (e > 9) continue;
        drow[x - box.x0] += static_cast<float>(s.strength * std::exp(-e) * floor_cover) * inv_n;
      }
    }
  }
  for (int y = box.y0; y <= box.y1; ++y) {
    uchar* row = out->ptr<uchar>(y);
    const float* drow = &dark[static_cast<size_t>(y - box.y0) * box.w()];
    for (int x = box.x0; x <= box.x1; ++x) {
      const float k = 1.0f - drow[x - box.x0];
      if (k >= 1.0f) continue;
      for (int c = 0; c < 3; ++c)
        row[3 * x + c] = cv::saturate_cast<uchar>(row[3 * x + c] * k);
    }
  }
}

void SynthScene::RenderBall(const std::vector<BallShape>& subs, const Bgr& color, bool seamed,
                            cv::Mat* out) const {
  struct Sub {
    cv::Point2d c;  // image centre
    Box box;
    double a, b;
    double spin_rad;
  };
  std::vector<Sub> s;
  Box box{0, 0, -1, -1};
  for (const auto& b : subs) {
    const cv::Point2d c = ToImage({b.x, b.y});
    const double ex = std::sqrt(b.a * b.a * cos_ * cos_ + b.b * b.b * sin_ * sin_) + 1.5;
    const double ey = std::sqrt(b.a * b.a * sin_ * sin_ + b.b * b.b * cos_ * cos_) + 1.5;
    s.push_back({c, ClipBox(c.x - ex, c.y - ey, c.x + ex, c.y + ey, config_.width,
                            config_.height),
                 b.a, b.b, b.spin_rad});
    box = Union(box, s.back().box);
  }
  if (box.empty()) return;
  // Per pixel: summed colour * alpha (3) and alpha (1), over the sub-exposures.
  std::vector<float> acc(static_cast<size_t>(box.w()) * box.h() * 4, 0.f);
  for (const Sub& b : s) {
    if (b.box.empty()) continue;
    const double ia = 1 / b.a, ib = 1 / b.b, ia2 = ia * ia, ib2 = ib * ib;
    BallSeams seams(seamed ? config_.seams : SeamPattern::kNone, config_.seam_width);
    seams.Turn(b.spin_rad);
    const double radius_px = 0.5 * (b.a + b.b);
    for (int y = b.box.y0; y <= b.box.y1; ++y) {
      float* arow = &acc[static_cast<size_t>(y - box.y0) * box.w() * 4];
      const double dy = y - b.c.y;
      for (int x = b.box.x0; x <= b.box.x1; ++x) {
        const double dx = x - b.c.x;
        // Ball-local offset, in scene axes.
        const double lx = cos_ * dx - sin_ * dy, ly = sin_ * dx + cos_ * dy;
        const double u = lx * ia, v = ly * ib;
        const double rho2 = u * u + v * v;
        // Signed distance to the outline, px (exact for a circle): rho - 1 over |grad rho|.
        const double rho = std::sqrt(rho2);
        double dist;
        if (rho < 1e-9) {
          dist = -std::min(b.a, b.b);
        } else {
          const double gx = lx * ia2, gy = ly * ib2;
          dist = (rho - 1) * rho / std::sqrt(gx * gx + gy * gy);
        }
        const double alpha = Clamp01(0.5 - dist);
        if (alpha <= 0) continue;
        float col[3];
        ShadeSphere(u, v, color, col);
        if (const double seam = seams.Coverage(u, v, radius_px); seam > 0) {
          float line[3];
          ShadeSphere(u, v, config_.seam_bgr, line);
          for (int c = 0; c < 3; ++c) col[c] += static_cast<float>(seam) * (line[c] - col[c]);
        }
        float* p = arow + 4 * (x - box.x0);
        for (int c = 0; c < 3; ++c) p[c] += static_cast<float>(alpha) * col[c];
        p[3] += static_cast<float>(alpha);
      }
    }
  }
  const float inv_n = 1.0f / static_cast<float>(subs.size());
  for (int y = box.y0; y <= box.y1; ++y) {
    uchar* row = out->ptr<uchar>(y);
    const float* arow = &acc[static_cast<size_t>(y - box.y0) * box.w() * 4];
    for (int x = box.x0; x <= box.x1; ++x) {
      const float* p = arow + 4 * (x - box.x0);
      const float alpha = p[3] * inv_n;
      if (alpha <= 0) continue;
      for (int c = 0; c < 3; ++c)
        row[3 * x + c] = cv::saturate_cast<uchar>(p[c] * inv_n + (1 - alpha) * row[3 * x + c]);
    }
  }
}

}  // namespace bouncefit
