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

// Slope of the least-squares line through (t, v); 0 when t does not vary.
inline double LineSlope(const std::vector<double>& t, const std::vector<double>& v) {
  const double n = static_cast<double>(t.size());
  double st = 0, sv = 0, stt = 0, stv = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    st += t[i];
    sv += v[i];
    stt += t[i] * t[i];
    stv += t[i] * v[i];
  }
  const double den = n * stt - st * st;
  if (!(den > 0)) return 0;
  return (n * stv - st * sv) / den;
}

// How far a least-squares line through (t, v) moves from the first time to the last.
inline double LineDrift(const std::vector<double>& t, const std::vector<double>& v) {
  return t.empty() ? 0 : LineSlope(t, v) * (t.back() - t.front());
}

}  // namespace bouncefit::detector_stats
