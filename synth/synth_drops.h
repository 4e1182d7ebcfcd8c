#pragma once
// Several drops in one clip, each at its own distance from the camera: a pinhole camera
// looking level from camera height (or down, raised to look at the first drop), so every drop has its own scale (px/m), ball size in px
// and floor line in the picture. The first drop starts held; each drop bounces to rest, the
// ball rolls along the floor to the next drop's distance (towards or away from the camera),
// an unseen hand lifts it to the next release height, holds it and lets go. The truth lists
// every drop (SynthTruth::drops) and, at the top level, all apexes and impacts in clip time
// with the first drop's scale and floor.
#include <vector>

#include "synth/synth_clip.h"

namespace bouncefit {

// The camera the drops are seen with: at height_m above the floor, looking down pitch_rad
// (0: level), focal length in px, its axis through the picture's centre.
struct SynthPinhole {
  double focal_px = 0;
  double height_m = 0;
  double pitch_rad = 0;
  double wall_distance_m = 0;  // the wall behind the drops: where the floor meets it

  // A point x_m right of the axis, up_m above the floor, distance_m along the floor from the
  // camera: its offset from the picture's centre per px of focal length (right, down), and
  // its depth along the axis, m.
  struct View {
    double right = 0, down = 0, depth_m = 0;
  };
  View See(double x_m, double up_m, double distance_m) const;
};

// The pinhole that fits every drop of c (c.drop_heights_m at c.drop_distances_m) into the
// frame: the highest release and the nearest floor line inside it, 5% from its edges.
SynthPinhole FitSynthPinhole(const SynthClipConfig& c);

// Renders c's drops (c.drop_distances_m non-empty; heights c.drop_heights_m, or
// c.drop_height_m for each). The clip lasts until the last drop has rested 0.5 s (c.duration_s
// is not used). Throws std::invalid_argument (one line) for a config it cannot render.
SynthClipResult RenderSynthDropsClip(const SynthClipConfig& c, const SynthProgress& progress = {});

}  // namespace bouncefit
