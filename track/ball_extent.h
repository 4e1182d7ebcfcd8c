#pragma once
// How large a box the ball can show. A ball of radius r moving at v over an exposure of at most
// one frame period covers its diameter plus its smear along the motion; a blob longer than
// that, or thinner than the ball while several balls long, is something else (the ball merged
// with a strip of floor or a same-coloured edge, or the strip alone), however close its pixel
// count comes to the ball's.

namespace bouncefit {

// The longest box side the ball can show, px: twice (a margin for smear beyond the exposure,
// a speed misjudged at an impact) its diameter plus its motion over one frame period.
double MaxBallExtentPx(double radius_px, double speed_px_s, double frame_period_s);

// Whether a box width x height px can hold the ball of radius_px (max_extent_px <= 0: the
// speed is unknown, only the shape is checked): not when thinner than 0.6 of the ball's
// diameter and longer than 1.5 of it (a ball cut by an edge is thin but short; smeared, long
// but as wide as itself). A box the search window cuts is at least as
// long as it shows, so the same test holds for it.
bool BoxCanBeBall(int width, int height, double radius_px, double max_extent_px);

}  // namespace bouncefit
