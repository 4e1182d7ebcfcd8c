#include "model/bounce_measure.h"

#include <algorithm>
#include <sstream>

#include "model/arc_apex.h"

namespace bouncefit {

MeasuredBounces MeasureBounces(const std::vector<double>& t, const std::vector<double>& y,
                               int window, double contact_height_m) {
  MeasuredBounces out;
  const size_t n = std::min(t.size(), y.size());
  std::vector<size_t> impacts;
  for (size_t k = 1; k + 1 < n; ++k)
    if (y[k] < y[k - 1] && y[k] <= y[k + 1]) impacts.push_back(k);
  for (size_t k : impacts) out.impact_times_s.push_back(t[k]);
  auto fit_arc = [&](size_t begin, size_t end, bool closed) {  // samples (begin, end)
    if (end <= begin + 1) return;
    size_t top = begin + 1;
    for (size_t k = begin + 1; k < end; ++k)
      if (y[k] > y[top]) top = k;
    if (!closed && end - 1 - top < static_cast<size_t>(window)) return;
    std::vector<double> ts, ys;
    const size_t lo = top > begin + static_cast<size_t>(window) ? top - static_cast<size_t>(window) : begin + 1;
    const size_t hi = std::min(end - 1, top + static_cast<size_t>(window));
    for (size_t k = lo; k <= hi; ++k)
      if (y[k] > contact_height_m) {
        ts.push_back(t[k]);
        ys.push_back(y[k]);
      }
    const ArcApex apex = FitArcApex(ts, ys);
    if (!apex.ok) return;
    // A parabola through a few samples of a hop of a millimetre (or of a ball at rest) can
    // put its vertex far off: a 1 mm hop read as 2.6 cm. A ballistic arc's apex lies among
    // its samples and at most g dt^2 / 8 above the top one (dt: the sample interval).
    const double dt = ts.size() > 1 ? (ts.back() - ts.front()) / static_cast<double>(ts.size() - 1) : 0;
    const double top_y = *std::max_element(ys.begin(), ys.end());
    if (apex.t < ts.front() - dt || apex.t > ts.back() + dt || apex.height > top_y + 9.81 * dt * dt / 8 + 1e-4)
      return;
    out.apex_times_s.push_back(apex.t);
    out.apex_heights_m.push_back(apex.height);
  };
  for (size_t i = 0; i + 1 < impacts.size(); ++i) fit_arc(impacts[i], impacts[i + 1], true);
  if (!impacts.empty()) fit_arc(impacts.back(), n, false);
  return out;
}

std::string SimulationOptionsError(const SimulationOptions& options) {
  if (!(options.drop_height_m > 0) || !(options.drop_height_m < 100))
    return "drop height must be in (0, 100) m";
  if (!(options.duration_s > 0) || !(options.duration_s <= 600))
    return "duration must be in (0, 600] s";
  if (options.record_trajectory && !(options.trajectory_rate_hz > 0))
    return "trajectory rate must be > 0";
  return {};
}

std::string TakeMeasuredBounces(const MeasuredBounces& measured, const SimulationOptions& options,
                                SimulationResult* result) {
  result->impact_times_s = measured.impact_times_s;
  for (size_t i = 0; i < measured.apex_heights_m.size(); ++i) {
    const double h = measured.apex_heights_m[i];
    if (h < options.min_bounce_height_m) break;
    const double previous = i == 0 ? options.drop_height_m : measured.apex_heights_m[i - 1];
    if (h > previous + 2e-2 * previous + 1e-4) {  // 2%: a hop of 1 cm may gain 0.2 mm in the contact
      // A stream: this file ships verbatim in the exported project (C++17 and Bullet only).
      std::ostringstream m;
      m.precision(4);
      m << "diverged (energy growth: bounce " << i + 1 << " at " << h << " m is higher than the one before, "
        << previous << " m)";
      return m.str();
    }
    result->bounce_heights_m.push_back(h);
    result->apex_times_s.push_back(measured.apex_times_s[i]);
  }
  return {};
}

}  // namespace bouncefit
