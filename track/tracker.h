#pragma once
// Finds the ball in one frame. The capture node and the run command use only this
// interface.
//
// Pipeline (the seed paper's, then better): Gaussian blur -> YCbCr (YUYV frames are read as
// they are) -> optional ROI -> chroma threshold around the ball colour (picked pixel, given
// colour, or chosen automatically: track/ball_finder.h, confirmed by track/arc_check.h) -> blobs with the paper's
// min/max box -> the blob nearest the parabolic prediction -> sub-pixel centre from a robust
// circle fit to the rim; a ball swept into a streak over the exposure is found by its coverage
// (track/ball_streak.h). Once locked it only looks in a window around the prediction; the
// whole frame (at half resolution) is searched only to (re)acquire.
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "capture/frame.h"
#include "track/arc_check.h"
#include "track/ball_centre.h"
#include "track/ball_finder.h"
#include "track/ball_observation.h"
#include "track/ball_segmenter.h"
#include "track/ball_streak.h"
#include "track/camera_motion.h"
#include "track/color_model.h"
#include "track/color_pick.h"
#include "track/luma_contrast.h"
#include "track/motion_predictor.h"
#include "track/ycc_planes.h"

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

class Tracker {
 public:
  // Throws std::invalid_argument for an invalid config.
  explicit Tracker(TrackerConfig config);
  // Frames must come in capture order; the tracker predicts the next position from them.
  // Throws std::invalid_argument for a frame that does not match its PixelFormat or a pick
  // point outside the first frame.
  BallObservation Track(const Frame& frame);
  // One line for the user: what colour it locked on and why.
  std::string Describe() const;

  // The ball followed, looked for again in an earlier frame (track/look_back_tracker.h): near
  // `centre` (pixels), as far as `reach_px` beyond its own radius, as a streak too where it may
  // sweep more than half its radius over the frame (`sweep_px`). Changes nothing the tracker
  // follows. False when not found, or with nothing to look with: no colour chosen yet, or
  // brightness (its background model is of now, not of then).
  // `replaces`: the frame had a sighting of its own (a tentative lock's), counted already.
  bool FindInEarlierFrame(const Frame& frame, cv::Point2f centre, double reach_px, double sweep_px,
                          BallObservation* obs, bool replaces = false);

  // The last frame's sighting is of an automatic lock not yet confirmed, seen only as a blob
  // running on out of the frame (an arm reaching in from its edge): the ball may be beside it,
  // and a later choice may find it there (the look back waits for it).
  bool tentative() const { return tentative_; }
  bool color_chosen() const { return color_.valid(); }
  const ColorModel& color() const { return color_; }
  int64_t acquisitions() const { return acquisitions_; }

 private:
  struct Candidate {
    Blob blob;
    double score = 0;
  };
  struct Remembered {
    cv::Point2f p;
    float r;
    bool at_choice = false;  // already there, of the ball's colour, when it was chosen
  };
  bool ChooseColor(const Frame& frame);
  bool AutoChoose(const Frame& frame);
  // While the automatic lock is not yet confirmed: confirm, replace or drop it.
  void ReviewAutoLock(const Frame& frame, const BallObservation& obs);
  void Adopt(const BallCandidate& c);
  // Remembers every blob of the chosen colour away from the ball: still things of its hue.
  void RememberLookalikes(const Frame& frame);
  bool Rejected(const BallCandidate& c, double t) const;
  // A candidate of the finder is the locked object: near where the lock was at the
  // candidate's time, and of its size.
  bool SameAsLock(const BallCandidate& c, double here_x, double here_y, double here_r) const;
  // A radius r (px) is the ball's of radius ref_r: within radius_change of it, and 1.5 px.
  bool SizeMatches(double r, double ref_r) const;
  bool CutByRoiBorder(const cv::Rect2f& box) const;
  double FollowedRadius() const;                    // radius_, or the finder's just after a choice
  // A close-up ball: one whose smeared box outgrows the segmenter's box limit (radius 85 px
  // and more with the default 220 px). Its box limit and, in brightness mode, the width of
  // the light changes removed grow with it.
  bool IsCloseUp(double radius_px) const;
  SegmenterParams SegmentParamsFor(double radius_px) const;
  // The square window of half-size `half` round `centre`, within the ROI.
  cv::Rect WindowRect(cv::Point2f centre, double half) const;
  // recentre: a close-up the window cuts is looked for once more in a window round it.
  bool TryWindow(const Frame& frame, cv::Point2f centre, double half, double gate,
                 BallObservation* obs, bool recentre = true);
  // The ball as a streak (track/ball_streak.h) in the window: its centre at mid-exposure, its
  // size the tracked radius (the streak's length is the sweep, not the ball). sweep_px: the
  // most the ball can move over an exposure.
  bool TryStreak(const Frame& frame, cv::Point2f centre, double half, double gate, double sweep_px,
                 BallObservation* obs);
  bool Acquire(const Frame& frame, BallObservation* obs);
  // expected: where the window looked for the ball (the prediction, or the blob itself).
  bool Refine(const Frame& frame, const Blob& blob, cv::Point2f expected, BallObservation* obs);
  void Adapt(double cx, double cy, double r);
  // ExtractYcc, or the contrast planes in brightness mode.
  void Planes(const Frame& frame, cv::Rect rect, int step, double blur_sigma_px, YccPlanes* out);
  // The part of the frame the ball followed may be in at time t (empty when none is followed).
  cv::Rect2d WhereBallMayBe(double t) const;
  // The predictor's position at t (in the scene) where this frame shows it.
  bool PredictInFrame(double t, double* x, double* y, double* speed = nullptr) const;
  // `contrast_luma`: how far the ball stands out of its surroundings (the finder's), 0: unknown.
  void StartLumaMode(int polarity, double contrast_luma = 0);
  void SetLumaFrame(const Frame& frame);  // the brightness lock's per-frame start

  TrackerConfig config_;
  cv::Rect roi_;
  cv::Size size_;
  ColorModel color_, anchor_;
  std::string how_;
  MotionPredictor predictor_;
  CameraMotion camera_;
  double cam_x_ = 0, cam_y_ = 0;  // this frame's camera motion (CameraMotion::dx, dy), pixels
  double radius_ = 0;        // tracked radius, pixels (0: unknown)
  int64_t lost_ = 1 << 20;   // frames since last found
  double last_t_ = 0;
  // The longest box side the ball can show this frame (track/ball_extent.h; 0: no
  // prediction, not checked).
  double max_extent_px_ = 0;
  double arc_speed_px_s_ = 0;        // the prediction's speed on the last arc it knew, px/s
  double arc_dir_x_ = 0, arc_dir_y_ = 0;  // ... and its direction (unit)
  double expected_motion_px_ = 1e9;  // the prediction's motion since the last sighting, px
  double last_frame_t_ = -1, frame_dt_s_ = 0;  // the frame period, s, from the last two frames (-1: none yet)
  int64_t frames_ = 0, found_ = 0, acquisitions_ = 0;
  int64_t found_earlier_ = 0;  // frames the ball was found in looking back
  bool looking_back_ = false;  // in FindInEarlierFrame: no colour adaptation
  // The last sighting was a blob the frame's (or ROI's) border cuts, with no rim found: all
  // that is known is that it runs on beyond (an arm reaching in), no shape to be a ball by. (A
  // ball the window alone cuts is a streak or a ball run into its shadow: it stays a ball.)
  bool shapeless_ = false;
  bool tentative_ = false;
  std::vector<Remembered> distractors_;
  std::vector<Blob> last_candidates_;
  BallFinder finder_;
  BallFinder still_finder_;  // the reviews of a still lock (still_review_work_pixels)
  ArcCheck arc_;
  bool auto_ = false;            // automatic choice, not yet confirmed by a ballistic arc
  BallCandidate chosen_;         // the automatic choice in force
  double last_found_t_ = 0;      // s
  double last_review_t_ = -1e9;  // s: when the finder last looked for a better candidate
  bool has_seed_ = false;        // where the chosen candidate was seen, to find it first
  bool lookalikes_pending_ = false;
  bool forget_ball_ = false;      // brightness mode chosen this frame: ball out of the background
  struct RejectedLock {
    double x, y, r, until_t;     // pixels, and until when (s) it stays rejected
  };
  std::vector<RejectedLock> rejected_;
  int64_t dropped_locks_ = 0, choices_ = 0;
  int64_t adapt_tick_ = 0;
  YccPlanes planes_, wide_;
  cv::Mat mask_;
  std::unique_ptr<LumaContrast> luma_;  // brightness mode only
  double last_cx_ = 0, last_cy_ = 0;   // last found centre, pixels
  double still_x_ = 0, still_y_ = 0;   // brightness mode: where the ball last moved to
  int64_t still_frames_ = 0;           // ... and frames since
};

}  // namespace bouncefit
