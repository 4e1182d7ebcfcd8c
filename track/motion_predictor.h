#pragma once
// Predicts where the ball will be in the next frame: a parabola in time through the recent
// centres of the current arc (free flight is a parabola whatever the camera roll). A
// measurement far from the prediction (a bounce, a throw) starts a new arc.
#include <cstdint>
#include <deque>

namespace bouncefit {

struct MotionPredictorParams {
  int history = 6;              // centres kept per arc
  double new_arc_px = 2.5;      // a miss larger than this starts a new arc, pixels
  double max_gap_s = 0.25;      // older history than this is forgotten, seconds
};

class MotionPredictor {
 public:
  explicit MotionPredictor(MotionPredictorParams params = {}) : params_(params) {}
  void Reset() { hist_.clear(); }
  bool empty() const { return hist_.empty(); }
  // Adds a measured centre at time t (seconds).
  void Add(double t, double x, double y);
  // Predicted centre and speed (pixels/s) at time t; false when there is no history.
  bool Predict(double t, double* x, double* y, double* speed_px_s = nullptr) const;
  int64_t arcs_started() const { return arcs_; }
  int samples() const { return static_cast<int>(hist_.size()); }  // of the current arc

 private:
  struct Sample {
    double t, x, y;
  };
  MotionPredictorParams params_;
  std::deque<Sample> hist_;
  int64_t arcs_ = 0;
};

}  // namespace bouncefit
