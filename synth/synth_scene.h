#pragma once
// One frame of the synth scene: a static camera looking at a wall and a floor, a shaded
// coloured ball, its soft shadow on the floor, an optional distractor, the whole scene
// rolled about the image centre. Motion blur is the average of sub-exposure renders; only
// the ball's and the shadow's small patches are rendered per sub-exposure.
//
// "Scene" coordinates are the image before roll (px, origin at the top-left pixel's
// centre, y down); image coordinates are after roll.
#include <opencv2/core.hpp>

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "synth/synth_seams.h"

namespace bouncefit {

using Bgr = std::array<double, 3>;  // colour, 0-255 per channel, B, G, R

// What covers the wall: plain paint; bricks of the wall colour in light mortar; or a poster
// wall of saturated patches of every hue (clutter that shares the ball's hue somewhere).
enum class WallPattern { kPlain, kBrick, kPoster };
// "plain", "brick", "poster"; throws std::invalid_argument for another name.
WallPattern ParseWallPattern(const std::string& name);
const char* WallPatternName(WallPattern pattern);

// What covers the floor: plain; or pebble tiles of many greys and browns in dark grout, each
// about a ball across and mottled, so that the floor shows edges and blobs of the ball's size.
enum class FloorPattern { kPlain, kPebble };
// "plain", "pebble"; throws std::invalid_argument for another name.
FloorPattern ParseFloorPattern(const std::string& name);
const char* FloorPatternName(FloorPattern pattern);

struct SynthSceneConfig {
  int width = 640, height = 480;   // px
  double roll_deg = 0;             // scene rotation, counter-clockwise on screen
  double floor_y_px = 412;         // scene y where the ball bottom touches the floor
  Bgr wall_bgr = {196, 202, 206};
  WallPattern wall_pattern = WallPattern::kPlain;
  Bgr floor_bgr = {112, 118, 124};
  FloorPattern floor_pattern = FloorPattern::kPlain;
  double pebble_px = 24;           // a pebble's size across, px
  Bgr ball_bgr = {20, 120, 250};
  bool distractor = false;         // a static sphere of similar hue resting on the floor
  double distractor_x_px = 0;      // its centre's scene x
  double distractor_radius_px = 10;
  // Lines painted on the ball (synth/synth_seams.h), this wide (share of its diameter), of
  // this colour, shaded as the ball is.
  SeamPattern seams = SeamPattern::kNone;
  double seam_width = 0.04;
  Bgr seam_bgr = {40, 40, 40};
};

// A hand at one instant, in scene px: a fist of radius r at (x, y) on an arm of its width that
// runs to the picture's side edge at scene x edge_x (where the arm leaves the picture).
struct HandShape {
  double x = 0, y = 0, r = 10;
  double edge_x = 0;
};

// The ball at one instant, in scene px.
struct BallShape {
  double x = 0, y = 0;        // centre
  double a = 10, b = 10;      // horizontal and vertical semi-axes (a = b: round ball)
  // Scene y of the floor line under the ball, where its shadow falls (NaN: the scene's
  // floor_y_px; a ball nearer the camera than the wall stands on a lower line).
  double floor_y = std::numeric_limits<double>::quiet_NaN();
  double spin_rad = 0;        // how far it has turned about its spin axis (its seams turn with it)
};

class SynthScene {
 public:
  explicit SynthScene(const SynthSceneConfig& config);

  const SynthSceneConfig& config() const { return config_; }
  cv::Point2d ToImage(cv::Point2d scene) const;
  cv::Point2d ToScene(cv::Point2d image) const;
  // The rendered static background (wall, floor, distractor), CV_8UC3.
  const cv::Mat& background() const { return background_; }
  // The ball (every pixel of it) lies inside the image.
  bool FullyInView(const BallShape& ball) const;

  // Renders into *out (CV_8UC3, the image size) the scene with the ball's exposure as the
  // average of the given sub-exposure shapes (at least one). Thread-safe.
  // A hand (nullptr: none) is drawn behind the ball, at the frame's mid-exposure.
  void Render(const std::vector<BallShape>& sub_exposures, cv::Mat* out, const HandShape* hand = nullptr) const;

 private:
  // Draws the arm and its fist over *out, skin-coloured, anti-aliased.
  void RenderHand(const HandShape& hand, cv::Mat* out) const;
  // Darkens *out by the exposure-averaged soft shadow of the shapes on the floor.
  void RenderShadow(const std::vector<BallShape>& subs, cv::Mat* out) const;
  // Composites the exposure-averaged shaded ball of the given colour over *out, the scene's
  // seams painted on it when `seamed`.
  void RenderBall(const std::vector<BallShape>& subs, const Bgr& color, bool seamed, cv::Mat* out) const;

  // The wall's colour at scene point q (before shading), per its pattern.
  Bgr WallColor(cv::Point2d q) const;
  // The floor's colour at scene point q (before shading), per its pattern.
  Bgr FloorColor(cv::Point2d q) const;

  SynthSceneConfig config_;
  std::vector<std::pair<cv::Rect2d, Bgr>> poster_;  // poster patches, scene px
  double cos_ = 1, sin_ = 0;   // of the roll
  cv::Point2d center_;         // rotation centre
  cv::Mat background_;
};

}  // namespace bouncefit
