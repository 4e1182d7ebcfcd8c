#pragma once
// The frame loop every synth clip shares: each frame's exposure as sub-exposure shapes of
// the ball, a hand-held camera's motion, sensor noise, the encoder, and the truth's per-frame
// record. What moves the ball (one drop, several drops) is a function of clip time.
#include <functional>
#include <vector>

#include "synth/synth_clip.h"
#include "synth/synth_scene.h"
#include "synth/synth_truth.h"

namespace bouncefit {

// The ball at one instant: its shape in scene px and its bottom above the floor, m.
struct SynthBallAt {
  BallShape shape;
  double bottom_m = 0;
  bool has_hand = false;  // a hand in the picture (SynthClipConfig::hand)
  HandShape hand;
};

// Process CPU time spent per phase, s.
struct SynthRenderCost {
  double scene_s = 0, noise_s = 0, encode_s = 0;
};

// The scene of a clip whose wall meets the floor at scene y floor_px; ball_radius_px sizes
// the distractor.
SynthSceneConfig SynthSceneConfigOf(const SynthClipConfig& c, double floor_px, double ball_radius_px);

// The truth's fields that describe the camera, the scene and the render (not the motion, not
// the frame count): the scale px_per_m and the floor line at scene y floor_px.
SynthTruth SynthTruthHeader(const SynthClipConfig& c, const SynthScene& scene, double px_per_m,
                            double floor_px);

// Renders one frame of `scene` per entry of `times` (taken at its real time, stamped with its
// file time) with the ball where ball_at(t) puts it, writes them to c.out (a constant rate
// through OpenCV, stamps of their own through FFmpeg's libraries) and appends each frame's
// record to truth->frames. Throws std::runtime_error (one line) when the clip cannot be written.
SynthRenderCost RenderSynthFrames(const SynthClipConfig& c, const SynthScene& scene,
                                  const std::vector<SynthFrameTime>& times,
                                  const std::function<SynthBallAt(double)>& ball_at,
                                  SynthTruth* truth, const SynthProgress& progress);

// Writes the truth next to the clip and gathers what the render cost: wall_s of wall time,
// process CPU time since cpu_start_s (SynthCpuSeconds), times per phase.
SynthClipResult FinishSynthClip(const SynthClipConfig& c, SynthTruth truth, const SynthRenderCost& times,
                                double wall_s, double cpu_start_s);

// Process CPU time (encoder threads included), s: on a shared machine the phases' wall
// times mostly measure the neighbours.
double SynthCpuSeconds();

}  // namespace bouncefit
