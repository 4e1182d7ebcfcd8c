#pragma once
// Whether a tracked object moves like a ball in flight: some stretch of its track is a
// parabola in time that accelerates downwards (free fall, whatever the horizontal speed),
// over a travel of at least a diameter. A hand, a swaying object or furniture that
// flickered never gives one; a ball gives one in its first fall or bounce.
#include <vector>

namespace bouncefit {

struct ArcCheckParams {
  int min_samples = 5;          // samples in a stretch
  double min_span_s = 0.12;     // a stretch lasts at least this long (more samples at high fps)
  double min_travel_radii = 1;  // vertical travel over the stretch, ball radii
  double max_rms_radii = 0.12;  // parabola fit residual, ball radii (at least max_rms_px)
  double max_rms_px = 0.8;
  double min_accel_radii = 1.5; // downward acceleration, ball radii/s^2 (slow motion included)
  double max_gap_s = 0.15;      // a longer gap between samples ends a stretch
};

class ArcCheck {
 public:
  explicit ArcCheck(ArcCheckParams params = {}) : params_(params) {}
  void Reset() { samples_.clear(), ballistic_ = false, moving_s_ = 0; }
  // A found position at time t (s), image pixels (y down), radius r (px). Returns true once
  // the stretch ending at this sample is a ballistic arc (and from then on). `whole`: the
  // object's outline seen, not a blob running on out of the frame; a stretch
  // with a sample that was not is no arc (an arm reaching in from the edge rises and slows as
  // a tossed ball does: its blob has no shape to tell it by).
  bool Add(double t, double x, double y, double r, bool whole = true);
  bool ballistic() const { return ballistic_; }
  // Time (s) the object spent moving (more than a radius per 0.1 s) without being ballistic.
  double moving_s() const { return moving_s_; }
  // Vertical travel over the last `span_s` seconds, px.
  double RecentTravel(double span_s) const;
  // The position added at time t (s, to a millisecond); false when none was.
  bool PositionAt(double t, double* x, double* y) const;

 private:
  struct Sample {
    double t, x, y, r;
    bool whole;
  };
  bool StretchIsArc() const;
  ArcCheckParams params_;
  std::vector<Sample> samples_;
  bool ballistic_ = false;
  double moving_s_ = 0;
};

}  // namespace bouncefit
