#pragma once
// Real-time pacing of a replayed stream against its capture times: the frame captured at
// stream time t is released at wall time start + (t - t_first) / speed. Speed 2 plays twice
// as fast; speed 0 does not wait at all. The clock is injected so tests need not sleep.
#include <cstdint>

namespace bouncefit {

class PacerClock {
 public:
  virtual ~PacerClock() = default;
  virtual int64_t NowMicros() = 0;                    // a monotonic clock
  virtual void SleepUntilMicros(int64_t deadline) = 0;
};

// std::chrono::steady_clock and std::this_thread::sleep_until.
PacerClock& SteadyPacerClock();

class Pacer {
 public:
  // Throws std::invalid_argument unless speed is finite and >= 0.
  explicit Pacer(double speed, PacerClock& clock = SteadyPacerClock());

  // Waits until the wall time at which stream time utime is due; returns how late that
  // moment already was, microseconds (0 when on time; always 0 at speed 0). The first call
  // anchors the stream to the wall clock; a stream time going backwards re-anchors.
  int64_t WaitFor(int64_t utime);
  // Forget the anchor: the next WaitFor starts a new timeline.
  void Reset() { anchored_ = false; }

  double speed() const { return speed_; }
  int64_t max_lateness_us() const { return max_late_; }

 private:
  double speed_;
  PacerClock& clock_;
  bool anchored_ = false;
  int64_t wall0_ = 0;
  int64_t stream0_ = 0;
  int64_t last_ = 0;
  int64_t max_late_ = 0;
};

}  // namespace bouncefit
