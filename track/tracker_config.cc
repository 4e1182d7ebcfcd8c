#include "track/tracker_config.h"

namespace bouncefit {

bool TrackerConfig::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (has_pick + has_color + has_chroma > 1) return fail("give either a pick point or a colour, not both");
  if (has_pick && (pick_x < 0 || pick_y < 0)) return fail("pick point must not be negative");
  for (double c : color_bgr)
    if (c < 0 || c > 255) return fail("colour components must be 0-255");
  if (roi_x < 0 || roi_y < 0 || roi_w < 0 || roi_h < 0) return fail("ROI must not be negative");
  if (blur_sigma_px < 0 || blur_sigma_px > 5) return fail("blur sigma must be 0-5 px");
  if (color.tolerance_rel <= 0 || color.tolerance_rel > 2) return fail("colour tolerance must be in (0, 2]");
  if (!(color.saturation_reach >= 1)) return fail("colour saturation reach must be >= 1");
  if (segment.min_box_px < 1 || segment.max_box_px <= segment.min_box_px)
    return fail("box limits must satisfy 1 <= min < max");
  if (!(max_line_share >= 0 && max_line_share <= 0.25)) return fail("line share must be in [0, 0.25] of the diameter");
  if (centre.rays < 8 || centre.rays > 1024) return fail("rays must be 8-1024");
  if (adapt_rate < 0 || adapt_rate > 1) return fail("adapt rate must be 0-1");
  if (finder.max_work_pixels < 1000) return fail("finder work size must be >= 1000 pixels");
  if (still_review_work_pixels != 0 && still_review_work_pixels < 1000)
    return fail("still-review work size must be 0 or >= 1000 pixels");
  if (finder.lag_s < 0) return fail("finder lag must be >= 0 s");
  if (!(auto_review_s >= 0)) return fail("review interval must be >= 0 s");
  if (luma.polarity < -1 || luma.polarity > 1) return fail("luma polarity must be -1, 0 or +1");
  if (luma.min_contrast_luma <= 0 || luma.clamp_luma <= luma.min_contrast_luma)
    return fail("luma contrast limits must satisfy 0 < min < clamp");
  if (luma.background_rate <= 0 || luma.background_rate > 1) return fail("background rate must be in (0, 1]");
  if (!(luma_contrast_share > 0) || !(luma_min_scale > 0 && luma_min_scale <= 1))
    return fail("luma contrast share must be > 0 and its least scale in (0, 1]");
  return true;
}

}  // namespace bouncefit
