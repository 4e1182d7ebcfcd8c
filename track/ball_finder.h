#pragma once
// The automatic choice of the ball: what a person finds at a glance. A candidate is what
// moved (a three-frame difference at reduced resolution: the region that differs from both
// the frame before and the frame after it), seen against its own surroundings: its colour,
// or its brightness when it has none, must differ from the ring around it, not be
// saturated in absolute terms (a red ball before a blue wall, a white ball before a dark
// cloth). Segmenting its neighbourhood with that colour must then give a round blob of its
// size that stands apart (not merged into a wall of the same hue). Whether its track becomes
// a ballistic arc is the tracker's check (track/arc_check.h).
#include <opencv2/core.hpp>

#include <deque>
#include <string>
#include <vector>

#include "capture/frame.h"
#include "track/color_model.h"
#include "track/picture_shift.h"

namespace bouncefit {

struct BallFinderParams {
  int max_work_pixels = 200000;    // frames are shrunk by 2, 4, ... to at most this many pixels
  double lag_s = 0.04;             // the three frames compared are this far apart (>= 1 frame)
  double min_change = 18;          // |dY|+|dCb|+|dCr| that counts as change (raised with noise), 0-255
  double max_changed_share = 0.25; // more of the frame changed: the camera or the light moved
  double min_radius_px = 2;        // smallest ball radius, work pixels
  double min_chroma_contrast = 0.12;  // ball vs surroundings, chroma/luma, to follow its colour
  double min_ball_chroma = 0.07;      // ... and the ball's own chroma/luma
  double min_luma_contrast = 22;      // ball vs surroundings, 0-255, to follow its brightness
};

// One candidate ball in the newest frame's coordinates (full-resolution pixels).
struct BallCandidate {
  double x = 0, y = 0, r = 0;  // centre and radius, pixels, as seen in the middle frame
  double t = 0;                // time of the middle frame, s
  bool by_luma = false;        // follow brightness (no usable colour)
  int polarity = 0;            // by_luma: +1 brighter than its surroundings, -1 darker
  ColorModel color;            // !by_luma: its colour
  double contrast = 0;         // against its surroundings: chroma/luma, or luma 0-255
  double weaker_colour = 0;    // by_luma: the colour it has, chroma/luma from its surroundings'
                               // (a step of brightness twice as large, in units of each, won)
  double roundness = 0;        // 0-1
  double score = 0;            // roundness x contrast x sqrt(area), frame pixels
  std::string Why() const;     // "moving round blob, colour ... against its surroundings ..."
};

class BallFinder {
 public:
  BallFinder(BallFinderParams params, ColorModelParams color) : params_(params), color_(color) {}
  // Feeds one frame (capture order) and returns the candidates it shows, best first;
  // `roi` in frame pixels. The first frames only fill the history.
  std::vector<BallCandidate> Find(const Frame& frame, cv::Rect roi);
  // Feeds one frame to the history only (what Find does first): for frames whose candidates
  // would not be looked at, so that a later Find still compares frames lag_s apart.
  void Remember(const Frame& frame, cv::Rect roi);
  void Reset() { history_.clear(); }

 private:
  struct Work {
    cv::Mat raw;  // the frame's region of interest, as delivered
    bool raw_borrowed = false;  // raw is the frame's own memory (Frame::owns_image), not a copy
    PixelFormat format = PixelFormat::kBgr24;
    cv::Mat ycc;  // CV_8UC3 Y, Cr, Cb at reduced resolution, once a Find needed it
    PictureProfiles profiles;  // of ycc, once a Find needed them (a hand-held camera's shift)
    cv::Mat spare;  // a buffer to compute ycc into
    double t = 0;
  };
  static constexpr size_t kHistory = 17;  // frames kept: two lags of up to 8 frames, and now
  Work& Push(const Frame& frame, cv::Rect roi);  // a new newest entry, its images empty
  const cv::Mat& Ycc(Work& w);                   // w's, converted from w.raw the first time
  const PictureProfiles& Profiles(Work& w);      // w's, from its ycc the first time
  // What changed in `b` against `other`, `other` first moved by the picture's shift to it.
  void ChangeAgainst(const cv::Mat& b, const cv::Mat& other, const PictureShift& shift, cv::Mat& d);
  void ToYcc(const cv::Mat& image, PixelFormat format, cv::Mat* ycc);
  BallFinderParams params_;
  ColorModelParams color_;
  std::deque<Work> history_;
  cv::Rect roi_;
  int shrink_ = 1;
  cv::Mat bgr_, small_, dba_, dbc_, labels_, moved_;  // scratch, kept to spare the allocations
};

}  // namespace bouncefit
