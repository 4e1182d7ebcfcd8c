#include "detect/watched_arcs.h"

#include <cmath>

namespace bouncefit {

void PictureCoverage::AddFrame(double t_s, bool found) {
  if (!any_) first_s_ = t_s;
  if (!found) {
    if (any_ && !last_found_ && !lost_.empty()) lost_.back().to_s = t_s;
    else lost_.push_back({t_s, t_s});
  }
  any_ = true;
  last_found_ = found;
  last_s_ = t_s;
}

bool PictureCoverage::FollowedThrough(double from_s, double to_s) const {
  // The frames run on past the arc's end and began before its start: it lies within the stream.
  if (!any_ || first_s_ >= from_s || last_s_ <= to_s) return false;
  for (const Span& s : lost_)
    if (s.to_s > from_s && s.from_s < to_s) return false;
  return true;
}

std::vector<bool> ArcsWatchedUnseen(const FusionResult& fused, const PictureCoverage& picture) {
  std::vector<bool> out(fused.flights.size(), false);
  int last_seen = -1;
  for (size_t i = 0; i < fused.impacts.size(); ++i)
    if (!std::isnan(fused.impacts[i].video_t_s)) last_seen = static_cast<int>(i);
  if (last_seen < 0) return out;
  for (size_t k = 0; k < fused.flights.size(); ++k) {
    const HeardFlight& fl = fused.flights[k];
    if (fl.from <= last_seen) continue;  // one end seen, or before the last seen impact
    const double start = fused.impacts[fl.from].t_s;
    out[k] = picture.FollowedThrough(start, start + fl.flight_s);
  }
  return out;
}

}  // namespace bouncefit
