#pragma once
// What the ball is segmented by once it is named or chosen: its colour (a chroma threshold
// that follows the ball's own slowly, never far from where it started), or, for a nearly
// colourless ball, its brightness against a background model (track/luma_contrast.h), which
// the ball is kept out of while it moves.
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>

#include "capture/frame.h"
#include "track/ball_observation.h"
#include "track/color_model.h"
#include "track/luma_contrast.h"
#include "track/tracker_config.h"
#include "track/ycc_planes.h"

namespace bouncefit {

class ColorLock {
 public:
  explicit ColorLock(const TrackerConfig& config) : config_(config) {}

  // The lock the config names (a colour given, as chroma, a pixel picked on `frame`, or
  // brightness); false when it names none (the choice is automatic). *how: what it locked
  // on, for the user. Throws std::invalid_argument for a pick point outside the frame.
  bool StartNamed(const Frame& frame, std::string* how);
  void StartColor(const ColorModel& color);
  // Brightness: brighter (+1), darker (-1) or either (0) than the background model.
  // `contrast_luma`: how far the ball stands out of its surroundings (the finder's; 0:
  // unknown). Returns what it follows, ": brightness, ...", for the user.
  std::string StartBrightness(int polarity, double contrast_luma = 0);
  void Drop();  // nothing locked

  bool valid() const { return color_.valid(); }
  bool brightness() const { return luma_ != nullptr; }
  // The colour, or in brightness mode the ball's "colour" in the contrast planes.
  const ColorModel& color() const { return color_; }

  // The planes `color()` applies to: ExtractYcc, or the contrast planes in brightness mode.
  void Planes(const Frame& frame, cv::Rect rect, int step, double blur_sigma_px, YccPlanes* out) const;
  // A ball's rim found well at (cx, cy), radius r in `planes` (a colour lock's): every 4th
  // such frame the colour moves towards the ball's interior, unless its surroundings look
  // like it.
  void Adapt(const YccPlanes& planes, double cx, double cy, double r);

  // Brightness mode only. The frame's luma, first thing each frame (LumaContrast::SetFrame).
  void SetFrame(const Frame& frame, double closeup_radius_px) { luma_->SetFrame(frame, closeup_radius_px); }
  // The ball chosen in the frame the background started from: taken out of it.
  void ForgetBall(double cx, double cy, double r) { luma_->ForgetBall(cx, cy, r); }
  double MovedFraction(cv::Rect2f box) const { return luma_->MovedFraction(box); }
  const cv::Mat& luma() const { return luma_->luma(); }
  // The frame's end: the background takes the frame in, except round the ball (last seen at
  // last_x, last_y, tracked radius `radius`) while it moves or has just come to rest.
  void UpdateBackground(bool found, const BallObservation& obs, double radius, double last_x, double last_y);

 private:
  const TrackerConfig& config_;
  ColorModel color_, anchor_;  // the colour now, and where it started
  int64_t adapt_tick_ = 0;
  std::unique_ptr<LumaContrast> luma_;  // brightness mode only
  double still_x_ = 0, still_y_ = 0;    // brightness mode: where the ball last moved to
  int64_t still_frames_ = 0;            // ... and frames since
};

}  // namespace bouncefit
