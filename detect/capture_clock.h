#pragma once
// The time each picture was taken, from the file's stamps, when the stamps say more than one
// rate. A phone's slow motion captures at a constant high rate (120, 240 fps) and stamps the
// pictures one capture period apart outside the slowed span and several inside it (1/30 s: 8x
// slower), with ramps between, and no tag says so. Read as stamped, a ball falling through the
// span's start slows to a crawl in mid-air and no parabola follows it.
//
// The capture period is the shortest step the stamps repeat (min_run steps in a row alike
// within a container's tick: a 1/240 s step on a 1/600 s tick alternates 3.3 and 5 ms), then
// the mean over every 12 steps in a row of one period since (alike, their mean within
// one_period of the period found: one step alone is a tick off it), and only a fast one (slow
// motion is filmed at 90 fps or more): a phone's ordinary video, whose rate wanders between 26
// and 30 fps, has none. A
// step at least min_slowdown periods long is a slowed one; min_run of them in a row show slow
// motion (one alone is a picture dropped). Until then the stamps are read as they are. A clock
// that knows the period from the start (constant_capture) reads every step as one period: the
// slowed steps, a ramp's steps into the span (shorter than min_slowdown periods) and a tick's
// rounding alike. Steps are read as they come: each picture's time is known when its stamp
// arrives. Whether the slowed steps were slow motion at all is the arcs' to say
// (detect/capture_clock_detector.h weighs their gravity against the ball's size on both
// readings). A core with no I/O.
#include <cmath>
#include <cstdint>
#include <deque>
#include <vector>

namespace bouncefit {

struct CaptureClockConfig {
  double max_capture_period_s = 1.0 / 90;  // slow motion is captured at 90 fps or faster
  int min_run = 4;                 // steps alike in a row that show a capture period
  double alike = 1.6;              // ... the longest at most this many times the shortest
  double one_period = 1.3;         // a step within this factor of the period is one (its mean)
  double min_slowdown = 1.8;       // a step this many capture periods long is slowed
  double known_period_s = 0;       // > 0: the capture period, known from the start
  // With known_period_s: every step is one capture period (the file is known to hold slow
  // motion, so it was captured at a constant rate: a ramp's steps of 1.2 or 2.5 periods too).
  bool constant_capture = false;
};

// The capture period of consecutive stamps (us) to a fraction of a microsecond, given a rough
// one: the median, over every 12 consecutive steps of one period (alike, their mean within
// one_period of the rough one), of their mean. A container's tick rounds each step (a 1/240 s
// step on a 1 ms tick: 4, 4, 4, 4, 4, 5 ms; on a 1/600 s tick: 3.3 and 5 ms in turn), a ramp
// into slow motion lengthens a few: neither moves a median of means. The rough period when no
// 12 steps of one period follow each other.
double CapturePeriodOfStamps(const std::vector<int64_t>& stamps, double rough_us,
                             const CaptureClockConfig& config = {});

class CaptureClock {
 public:
  explicit CaptureClock(CaptureClockConfig config = {})
      : config_(config), period_us_(config.known_period_s * 1e6), anchor_us_(period_us_) {}
  // The next picture's stamp, us (equal or earlier ones change nothing), and its index in the
  // stream (-1: not known); returns the time it was taken on the capture clock, us (the first
  // picture's stamp + the real steps). Pictures the index skips (lost on the way, or repeats
  // left out) were taken all the same: a step over n of them is n steps, never a slowed one.
  int64_t Add(int64_t utime, int64_t index = -1);
  // The capture time of the last stamp added, us.
  int64_t last_taken() const { return std::llround(taken_us_); }
  double capture_period_s() const { return period_us_ * 1e-6; }  // 0: none found
  int64_t slowed_steps() const { return slowed_steps_; }
  // The most slowed steps in a row: min_run of them show slow motion (fewer: pictures dropped).
  int64_t longest_slowed_run() const { return longest_slowed_run_; }
  bool shows_slow_motion() const { return longest_slowed_run_ >= config_.min_run; }
  // Times the capture period was found or found shorter (the steps before were read by the
  // longer one, or as stamped).
  int period_changes() const { return period_changes_; }
  double max_slowdown() const { return max_slowdown_; }  // longest slowed step / capture period
  // Seconds of stamps the slowed steps span, and the real seconds they were.
  double slowed_stamp_s() const { return slowed_stamp_us_ * 1e-6; }
  double slowed_real_s() const { return slowed_steps_ * capture_period_s(); }

 private:
  // Counts a step over `pictures` pictures at least min_slowdown periods long a picture (true)
  // or ends a run of them (false).
  bool CountSlowed(int64_t step, int64_t pictures);

  CaptureClockConfig config_;
  bool started_ = false;
  int64_t last_ = 0, last_index_ = -1;
  double taken_us_ = 0;
  std::deque<int64_t> recent_;      // the last min_run steps
  double period_us_ = 0;
  double anchor_us_ = 0;            // the period as found (from min_run steps)
  std::deque<int64_t> window_;      // the last steps of one picture that were not slowed
  double period_sum_us_ = 0;        // the means of windows of one period since it was found
  int64_t period_steps_ = 0;        // ... how many
  int period_changes_ = 0;
  int64_t slowed_steps_ = 0, slowed_stamp_us_ = 0;
  int64_t slowed_run_ = 0, longest_slowed_run_ = 0;
  double max_slowdown_ = 1;
};

}  // namespace bouncefit
