#pragma once
// Brightness mode for near-colourless balls (a white ping-pong ball on a light wall): the
// tracker's colour machinery runs unchanged on "contrast planes" in which the chroma U is the
// luma difference of the frame against a background model, clamped to +-clamp_luma and signed
// so that the ball's side is positive; Y is a constant and V zero. The ball colour is then a
// point (nu > 0, 0): pixels brighter (or darker) than the background by more than
// min_contrast_luma match, and the rim unmixing of FindBallCentre sees the ball over a flat
// background.
//
// The background is a running mean of full-resolution luma, started from the first frame and
// updated everywhere except around the ball's last known position (so a ball at rest does
// not fade into it). A ball held still in the first frame leaves a trace of the opposite sign,
// which the polarity ignores.
//
// Cost: only what the tracker looks at is computed at full resolution (the contrast of a
// window); the per-frame work on the whole frame is one 8-bit luma conversion, one blend of
// it into the background, and the global drift and soft shadows measured on an 8x smaller
// copy (docs/PERFORMANCE.md).
#include <opencv2/core.hpp>

#include "capture/frame.h"
#include "track/color_model.h"
#include "track/ycc_planes.h"

namespace bouncefit {

struct LumaContrastParams {
  int polarity = +1;              // +1: ball brighter than the background, -1: darker, 0: either
  double min_contrast_luma = 15;  // least luma difference of a ball pixel, 0-255 units
  double clamp_luma = 40;         // differences beyond this count as this, 0-255 units
  double background_rate = 0.05;  // running-mean weight of each new frame, 0-1
  double highpass_sigma_px = 32;  // soft changes wider than this are removed (0: off), pixels
  double closeup_highpass_radii = 2.5;  // a close-up ball: only changes wider than this many radii removed
  double keep_out_radii = 1.8;     // not updated within this many ball radii (+4 px) of the ball
  double motion_luma = 12;        // frame-to-frame luma change that counts as motion, 0-255
};

class LumaContrast {
 public:
  explicit LumaContrast(LumaContrastParams params) : params_(params) {}
  // The ball "colour" in contrast planes, for the tracker's ColorModel.
  static ColorModel BallModel(const LumaContrastParams& params, ColorModelParams color);

  // Reads the frame's luma (whole frame, full resolution); starts the background on the
  // first call. Call once per frame, before ContrastPlanes. `closeup_radius_px`: the radius of
  // a close-up ball followed (0: none; the tracker decides what a close-up is), which keeps
  // its body from being taken for a soft change of light.
  void SetFrame(const Frame& frame, double closeup_radius_px = 0);
  // Contrast planes of `rect` of the current frame, decimated by `step` (1 or 2) and blurred
  // by `blur_sigma_px` (output pixels), in the layout of ExtractYcc.
  void ContrastPlanes(cv::Rect rect, int step, double blur_sigma_px, YccPlanes* out) const;
  // Blends the current frame into the background, except within the keep-out circle around
  // (cx, cy) of radius r (r <= 0: no keep-out).
  void UpdateBackground(double cx, double cy, double r);
  // Paints the disc of radius 1.5 r around (cx, cy) in the background with the mean of the
  // ring around it: a ball present in the frame the background started from leaves it.
  void ForgetBall(double cx, double cy, double r);

  // Share of the pixels in `box` (frame pixels) whose luma changed by more than
  // motion_luma since the previous frame: a ghost (where a ball held still in the background
  // model has left) or a brightened patch does not move; a ball in flight does.
  double MovedFraction(cv::Rect2f box) const;

  const LumaContrastParams& params() const { return params_; }
  // The last frame's luma (CV_8U; of a YUYV frame, rescaled to full range).
  const cv::Mat& luma() const { return grey_; }

 private:
  static constexpr int kSoftScale = 8;  // the drift and soft-change copies are this much smaller
  // Takes the soft change (bilinear from its small copy) from `diff`, the contrast of `rect`
  // decimated by `step`.
  void SubtractSoftChange(cv::Rect rect, int step, cv::Mat* diff) const;
  LumaContrastParams params_;
  cv::Mat grey_, previous_;  // CV_8U: this frame's luma and the previous frame's
  cv::Mat background_;       // CV_32F, frame size
  cv::Mat soft_now_, soft_background_;  // CV_32F, kSoftScale smaller
  cv::Mat soft_change_;      // CV_32F, kSoftScale smaller: the soft part of the difference, removed
  float offset_ = 0;         // the whole frame's drift against the background, luma
  cv::Mat keep_mask_, saved_;  // the keep-out disc (CV_8U) and the background under it, its box
  cv::Mat soft_keep_mask_;     // CV_8U: where the small copy is updated
};

}  // namespace bouncefit
