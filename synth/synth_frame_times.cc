#include "synth/synth_frame_times.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace bouncefit {

std::string SynthTimelineConfig::Validate(double fps) const {
  if (!(slow_motion >= 1 && slow_motion <= 64)) return "slow motion must be in [1, 64] (1: none)";
  if (slow_motion > 1 && !(slow_to_s > slow_from_s && slow_from_s >= 0))
    return "slow motion needs 0 <= --slow-from < --slow-to (real seconds)";
  if (!(vfr_min_fps >= 0) || (vfr_min_fps > 0 && vfr_min_fps >= fps))
    return "the variable rate's lowest fps must be > 0 and below --fps";
  if (vfr_min_fps > 0 && slow_motion > 1) return "a variable rate and slow motion do not mix";
  if (!(slow_ramp_s >= 0) || (slow_motion > 1 && 2 * slow_ramp_s > slow_to_s - slow_from_s))
    return "the slow-motion ramps must be >= 0 s and fit twice into the slowed span";
  return {};
}

std::vector<SynthFrameTime> SynthFrameTimes(const SynthTimelineConfig& c, double fps,
                                            double duration_s, uint64_t seed) {
  std::vector<SynthFrameTime> out;
  if (c.vfr_min_fps > 0) {
    std::mt19937_64 rng(seed * 0xD1B54A32D192ED03ull + 5);
    std::uniform_real_distribution<double> period(1 / fps, 1 / c.vfr_min_fps);
    // Stamps on the microsecond: a container's clock has a tick too.
    for (double t = 0; t < duration_s - 1e-9; t = std::round((t + period(rng)) * 1e6) / 1e6)
      out.push_back({t, t});
    return out;
  }
  const int n = std::max(1, static_cast<int>(std::lround(duration_s * fps)));
  double file = 0;
  for (int i = 0; i < n; ++i) {
    const double real = i / fps;
    if (i > 0) {
      const double before = (i - 1) / fps;
      double k = 1;
      if (before >= c.slow_from_s - 1e-9 && before < c.slow_to_s - 1e-9) {
        // Inside the span: the slow-down ramps up from its start and down to its end.
        const double edge = std::min(before - c.slow_from_s, c.slow_to_s - before);
        k = c.slow_ramp_s > 0 && edge < c.slow_ramp_s
                ? 1 + (c.slow_motion - 1) * std::max(0.0, edge) / c.slow_ramp_s
                : c.slow_motion;
      }
      file += k / fps;
    }
    out.push_back({real, file});
  }
  return out;
}

}  // namespace bouncefit
