#pragma once
// Heard arcs the picture watched and did not see. A core with no I/O.
//
// Past the last impact the picture saw, a heard bounce train goes on lower and lower. Where
// the tracker found the ball in every frame of an arc and the detector still saw neither of
// its impacts, the picture followed the ball through that arc and showed no bounce it could
// tell from the ball settling: a hop too low for the picture, and for a person watching it.
// It stays an impact (impacts.csv), not an apex. The arc that begins at the last seen impact
// is the picture's own last arc, seen to begin; where the tracker lost the ball (out of view,
// hidden) the sound alone speaks for the arc. Before the first seen impact the picture had
// not found the ball, and a bounce heard between two seen ones is higher than the seen one
// after it: there the picture's silence is a lapse, not a hop too low, so the rule holds only
// past the last seen impact.
#include <vector>

#include "detect/impact_fusion.h"

namespace bouncefit {

// The frames of the stream, as far as the rule needs them: where the ball was not found.
class PictureCoverage {
 public:
  // One frame at t_s (video clock, ascending), the ball found in it or not.
  void AddFrame(double t_s, bool found);
  // The frames span (from_s, to_s) and the ball was found in every one of them.
  bool FollowedThrough(double from_s, double to_s) const;

 private:
  struct Span {
    double from_s = 0, to_s = 0;  // first and last frame of a run of frames without the ball
  };
  std::vector<Span> lost_;
  double first_s_ = 0, last_s_ = 0;
  bool any_ = false, last_found_ = true;
};

// One entry per flight of `fused`: true where the picture watched the arc and did not see it
// (both impacts heard only, past the last seen impact, the ball followed through it).
std::vector<bool> ArcsWatchedUnseen(const FusionResult& fused, const PictureCoverage& picture);

}  // namespace bouncefit
