#pragma once
// How a drop starts. While no drop is in flight the samples gather as a hold; a drop starts
// at one of:
//  - a release: the ball held still, then a move down from the hold;
//  - a fall whose release the tracker missed (it found the ball only once it fell): a few
//    samples each further down than the last, accelerating, near the vertex they fit;
//  - an arc entered mid-flight (thrown, or already bouncing when the clip began): a few
//    samples on one parabola, accelerating down. Its apex, when seen, is bounce 0 if the ball
//    was seen before it, where the arc leads back to (thrown from the hand), and bounce 1
//    otherwise (it came from an impact out of sight).
// After a drop that ended at rest, the ball moved again (picked up, kicked) brings back the
// waiting. What it knew of an entered arc's beginning (the lowest sample just before it,
// the last sample seen before it) decides, at the first impact, how the arc began.
#include <cstdint>
#include <optional>
#include <vector>

#include "detect/detector_scene.h"

namespace bouncefit {

// How a drop starts (fields of BounceDetectorConfig).
struct DropStartConfig {
  double release_px = 1.5;      // a move down of at least this (and the gate) starts a drop
  double max_hold_drift = 0.5;  // a hold drifts less than this fraction of that move
  // No hold seen (the tracker found the ball only once it fell): this many samples, each
  // further down than the last, accelerating, over twice that move, start a drop whose
  // release height is the fitted vertex of the fall.
  int fall_start_samples = 5;
  // Any other arc (thrown, already bouncing): this many samples on one parabola.
  int arc_start_samples = 5;
  // A fall first seen this close to its vertex (or 2 frames) is a release whose hold was
  // missed (bounce 0 is the vertex); one seen later came from out of view.
  double unseen_release_max_s = 0.08;
  // The picture's size, px (0: not known). With it, a fall first seen later than that, its
  // vertex in the picture and nothing seen rising into it while the camera watched, is known
  // at its first impact for a release whose hold the tracker missed (a finder that sees what
  // moves finds a still ball only once it falls, later when the camera shakes).
  int image_width_px = 0, image_height_px = 0;
  double hold_window_s = 0.25;  // hold samples kept in the release arc
};

// A drop's start: its first arc and the number of that arc's bounce.
struct DropStartFound {
  DetectorArc arc;
  int first_bounce = 0;
};

class DropStart {
 public:
  DropStart(const DropStartConfig& config, DetectorScene& scene);

  // A sample while no drop is in flight: the drop it starts, if it does. The hold then
  // begins anew.
  std::optional<DropStartFound> OnWaiting(const DetectorSample& s);
  // A sample after a drop ended at rest: true when the ball moved away from where it rested
  // (three samples), which begins the waiting for a release anew.
  bool PickedUp(const DetectorSample& s);
  // A frame without the ball at time t: a hold not seen for lost_s is forgotten.
  void ForgetStaleHold(double t, double lost_s);
  // The drop ended: the hold and the rest begin anew.
  void Reset();
  void RescaleTime(double k);

  // At the first impact, for the drop's first arc taken as entered: the ball was seen down
  // at the floor just before it (it came from an impact out of sight).
  bool EnteredFromTheFloor() const;
  // At the first impact: the drop's first arc, taken for one entered from out of view, was a
  // fall from a hold the tracker did not see (DropStartConfig::image_width_px).
  bool EnteredFallWasAnUnseenRelease(const DetectorArc& first) const;

  const DropStartConfig& config() const { return config_; }

 private:
  std::optional<DropStartFound> ReleasedFromHold();
  std::optional<DropStartFound> FallFromUnseenRelease();
  std::optional<DropStartFound> ArcFromUnseenStart();
  // Forgets the hold and keeps what is known of how the found arc began.
  DropStartFound Found(DetectorArc arc, int first_bounce = 0,
                       std::optional<DetectorSample> low_before = std::nullopt,
                       int64_t seen_before_utime = INT64_MAX);
  // bend_slowdown: the slow-down a fall's bend says (SlowdownOfBend), while the clock is
  // undecided.
  double UnseenReleaseMaxS(double bend_slowdown = 1) const;
  // Whether the ball was seen rising into the vertex of the fall made by the last m samples
  // held: one free flight from a sample lower than its top, beyond a hold's jitter. The
  // longest such flight's vertex time, when there is one.
  bool SeenRisingIntoFall(size_t m, double* t_vertex) const;
  // How many samples just before hold_[first] lie on the parabolas Down = cu0 + cu1 dt + cu2
  // dt^2 and Floor = cw0 + ... (dt from t_ref) within tol, back to back (gaps of 3 frames at
  // most, or one the arc spent above the picture: the sample before it within the start gate).
  size_t OnArcBefore(size_t first, const Eigen::Vector3d& cu, const Eigen::Vector3d& cw,
                     double t_ref, double tol) const;
  // Whether between samples a and b (a gap in them) the ball reached above the picture's top,
  // out of it or cut by it (its centre not placed): on the parabola Down = cu (dt from t_ref)
  // its top is above the picture halfway between them.
  bool AboveTheTopBetween(const DetectorSample& a, const DetectorSample& b, const Eigen::Vector3d& cu,
                          double t_ref) const;
  double Down(const DetectorSample& s) const { return scene_.Down(s); }
  double Floor(const DetectorSample& s) const { return scene_.Floor(s); }

  DropStartConfig config_;
  DetectorScene& scene_;
  std::vector<DetectorSample> hold_;
  std::vector<DetectorSample> rest_samples_;
  int rest_moves_ = 0;
  // An entered first arc: the lowest sample seen shortly before it (was it at the floor?).
  std::optional<DetectorSample> low_before_entered_;
  // ... and when the ball was last seen before it (INT64_MIN: never; INT64_MAX: not known).
  int64_t seen_before_entered_utime_ = INT64_MAX;
};

}  // namespace bouncefit
