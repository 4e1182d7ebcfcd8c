#pragma once
// Every tunable of the tracker and its parts (track/tracker.h), with its default: how the
// ball is named (or chosen automatically), the region looked at, and each part's limits.
#include <string>

#include "track/arc_check.h"
#include "track/ball_centre.h"
#include "track/ball_finder.h"
#include "track/ball_segmenter.h"
#include "track/camera_motion.h"
#include "track/color_model.h"
#include "track/luma_contrast.h"
#include "track/motion_predictor.h"

namespace bouncefit {

struct TrackerConfig {
  // Ball colour: a pixel to pick on the first frame, or a colour, or neither (automatic).
  bool has_pick = false;
  double pick_x = 0, pick_y = 0;    // pixels
  bool has_color = false;
  double color_bgr[3] = {0, 0, 0};  // B, G, R 0-255
  std::string color_name;           // how the user named it, for Describe()
  // ... or as luma-normalised chroma (Cb-128, Cr-128) / Y, as picked in a window on a frame
  // the tracker may never see (a live camera's first frame).
  bool has_chroma = false;
  double chroma_nu = 0, chroma_nv = 0;
  // Brightness mode for a near-colourless ball (track/luma_contrast.h): segment on luma
  // contrast against a background model instead of chroma. Set by `--color white|black`, or
  // by a pick on a nearly grey pixel (polarity from the pick against its surroundings).
  bool luma_mode = false;
  LumaContrastParams luma;
  int luma_still_frames = 15;       // a ball still for longer may fade into the background
  double luma_contrast_share = 0.35;  // a brightness lock's threshold: this share of the contrast
                                      // the finder saw, if below luma.min_contrast_luma ...
  double luma_min_scale = 0.4;        // ... down to this share of it (its clamp scales alike)
  // Region of interest, pixels; width or height 0 = whole frame.
  int roi_x = 0, roi_y = 0, roi_w = 0, roi_h = 0;

  double blur_sigma_px = 1.0;       // Gaussian blur before thresholding, pixels
  // Measure a hand-held camera's motion (track/camera_motion.h) and report it with each
  // frame, so that the ball is measured against the scene.
  bool follow_camera = true;
  CameraMotionParams camera;
  ColorModelParams color;           // chroma tolerance
  SegmenterParams segment;          // min/max box and shape limits
  BallCentreParams centre;          // sub-pixel rim fit
  MotionPredictorParams motion;     // parabolic prediction
  // A streak's slope may differ from the path's before it by this much, degrees.
  double streak_max_turn_deg = 30;
  double window_margin_px = 8;      // search window beyond radius + expected motion, pixels
  double gate_px = 6;               // a blob may be this far beyond radius + motion from the prediction, pixels
  double radius_change = 0.4;       // a blob whose radius differs more (relative) is not the ball
  // Lines of another colour painted on the ball (seams, panel lines) up to this share of its
  // diameter wide are bridged: the pieces they cut its colour into are one blob when together
  // they are round (track/split_ball.h). Motion blur widens them: a falling basketball's
  // channels, a fortieth of its diameter, blur to a fifth of it at 30 fps. 0: never.
  double max_line_share = 0.22;
  int lost_frames_keep = 30;        // frames the prediction still guides re-acquisition
  // Threshold adaptation: each good frame moves the colour this much towards the ball's
  // measured interior colour, never further than max_drift (relative to |colour|) from the
  // initial one, and never when the surroundings look like the ball.
  double adapt_rate = 0.02;
  double adapt_max_drift = 0.3;
  // Automatic choice: candidates from track/ball_finder.h; the lock is kept once its track
  // becomes a ballistic arc (track/arc_check.h). Until then a better candidate elsewhere
  // replaces a lock that is standing still, and a lock that moves for auto_drop_moving_s
  // without an arc is dropped (and not chosen again for auto_reject_s).
  BallFinderParams finder;
  ArcCheckParams arc;
  double auto_drop_moving_s = 1.2;
  double auto_drop_lost_s = 1.0;
  double auto_reject_s = 3;
  // While an unconfirmed lock stands still (a ball held before the drop), the finder looks
  // for a better candidate at most this often (it only keeps the frames between): a switch
  // from a still decoy to the dropped ball waits at most this long. A new choice is
  // reviewed at once. s.
  double auto_review_s = 0.05;
  // Those reviews of a still lock look at frames shrunk to at most this many pixels (0: the
  // finder's own size): most of a held ball's tracking time went to them, at full size on a
  // small clip (docs/PERFORMANCE.md).
  int still_review_work_pixels = 50000;

  // False with a one-line reason if a value is out of range.
  bool IsValid(std::string* error) const;
};

}  // namespace bouncefit
