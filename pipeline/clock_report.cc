#include "pipeline/clock_report.h"

#include <fmt/format.h>

#include <cmath>

namespace bouncefit {

std::string ClockReport::Update(const Calibration& c) {
  const double q = c.gravity_over_size;
  if (!(q > 0)) return {};
  std::string r;
  if (c.time_scale != 1) {
    r = fmt::format("clock: slow motion: the file plays {:.2f}x slower than real time", 1 / c.time_scale);
    if (container_.capture_fps > 0)
      r += fmt::format(" ({} {:.0f} fps, stored at {:.2f} fps)", container_.tag, container_.capture_fps,
                       container_.stored_fps);
    else if (c.time_scale < 1 && !forced_)
      r += " (the file does not say so; the free fall against the ball's size does, by more "
           "than a ball of another preset would: --time-scale 1 to read it as recorded)";
    r += fmt::format("; times and heights use real time; gravity's scale is {:.2f}x the ball size's", q);
    if (std::abs(std::log(q)) > std::log(1.3) && c.diameter_ratio > 0)
      r += fmt::format(" (the ball measures {:.2f}x the size given on the free fall's scale: another ball than the preset?)",
                       c.diameter_ratio);
  } else if (c.method == "ball-diameter" && c.free_fall_px_per_m > 0) {
    // Too uncertain to say anything about the clock: no slow motion to suggest.
    r = fmt::format("clock: as recorded; the free fall is not measured (its scale {:.0f} +- {:.0f} px/m): "
                    "heights use the ball's size, {:.0f} px/m",
                    c.free_fall_px_per_m, c.free_fall_sigma, c.px_per_m);
  } else {
    r = fmt::format("clock: as recorded; gravity's scale is {:.2f}x the ball size's", q);
    if (std::abs(std::log(q)) > std::log(1.3))
      r += fmt::format(" (they disagree: a ball of another size than given, or a timeline slowed {:.2f}x: "
                       "--time-scale {:.3f} if so)",
                       1 / std::sqrt(q), std::sqrt(q));
  }
  // Two scales more than 10% apart: which one the heights use, and what the other would mean.
  if (std::abs(std::log(q)) > std::log(1.1) && c.px_per_m > 0 && c.method != "ball-diameter")
    r += fmt::format("; heights use the {} scale, {:.0f} px/m; the ball's size gives {:.0f} px/m: were it right, "
                     "every height would be {:.2f}x (restitution, a ratio of speeds, is the same either way)",
                     c.method == "free-fall" ? "free fall's" : c.method, c.px_per_m, c.free_fall_px_per_m / q,
                     c.px_per_m / (c.free_fall_px_per_m / q));
  // Said again only when it changes the answer: another clock, another scale's source, or
  // the two scales coming to agree or disagree.
  const std::string kind = fmt::format("{} {} {} {}", c.time_scale, c.method,
                                       std::abs(std::log(q)) > std::log(1.3), c.method == "ball-diameter");
  text_ = r;
  if (kind == kind_) return {};
  kind_ = kind;
  return r;
}

}  // namespace bouncefit
