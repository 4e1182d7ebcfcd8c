#pragma once
// Small statistics the bounce detector's files share (internal to detect/).
#include <algorithm>
#include <vector>

namespace bouncefit::detector_stats {

inline double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// A least-squares line through points (t, v), weighted (w empty: all alike): its weighted
// means and slope (0 when t does not vary).
struct Line {
  double mean_t = 0, mean_v = 0, slope = 0;
  double At(double t) const { return mean_v + slope * (t - mean_t); }
};
inline Line FitLine(const std::vector<double>& t, const std::vector<double>& v,
                    const std::vector<double>& w = {}) {
  Line line;
  double sw = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double wi = w.empty() ? 1.0 : w[i];
    sw += wi, line.mean_t += wi * t[i], line.mean_v += wi * v[i];
  }
  if (!(sw > 0)) return line;
  line.mean_t /= sw, line.mean_v /= sw;
  double stt = 0, stv = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double wi = w.empty() ? 1.0 : w[i], dt = t[i] - line.mean_t;
    stt += wi * dt * dt, stv += wi * dt * (v[i] - line.mean_v);
  }
  if (stt > 0) line.slope = stv / stt;
  return line;
}

// Slope of the least-squares line through (t, v); 0 when t does not vary.
inline double LineSlope(const std::vector<double>& t, const std::vector<double>& v) {
  return FitLine(t, v).slope;
}

// How far a least-squares line through (t, v) moves from the first time to the last.
inline double LineDrift(const std::vector<double>& t, const std::vector<double>& v) {
  return t.empty() ? 0 : LineSlope(t, v) * (t.back() - t.front());
}

// c0 + c1 dt + c2 dt^2 of a column of parabola coefficients (as DownParabola, or a column of a
// fit in both image axes, gives them).
template <typename Coeffs>
double ParabolaAt(const Coeffs& c, double dt) {
  return c(0) + c(1) * dt + c(2) * dt * dt;
}

}  // namespace bouncefit::detector_stats
