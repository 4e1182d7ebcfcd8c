#include "detect/frame_retiming.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "detect/detector_stats.h"

namespace bouncefit {

namespace {

using detector_stats::Median;

// Round rates first (see the choice below).
constexpr double kSourceFps[] = {24, 25, 30, 48, 50, 60, 90, 100, 120, 23.976, 29.97, 59.94, 119.88};

double Seconds(int64_t utime) { return static_cast<double>(utime) * 1e-6; }

// |third divided difference| of the heights over four (time, height) points, px/s^3.
double ThirdDifference(const double t[4], const double y[4]) {
  double d1[3], d2[2];
  for (int k = 0; k < 3; ++k) d1[k] = (y[k + 1] - y[k]) / (t[k + 1] - t[k]);
  for (int k = 0; k < 2; ++k) d2[k] = (d1[k + 1] - d1[k]) / (t[k + 2] - t[k]);
  return std::abs((d2[1] - d2[0]) / (t[3] - t[0]));
}

double Tick(double t, double f, double c) { return std::floor(t * f + c + 1e-9) / f; }

}  // namespace

std::vector<BallObservation> FrameRetimer::Push(const BallObservation& obs) {
  if (last_utime_ >= 0) {
    const double dt = Seconds(obs.utime - last_utime_);
    if (period_s_ == 0) period_s_ = dt;
    if (dt <= 0 || std::abs(dt - period_s_) > config_.uniform_tolerance * period_s_) uniform_ = false;
  }
  last_utime_ = obs.utime;
  if (retiming_.decided) return {Applied(obs)};
  if (!uniform_) {
    Decide(false);
    held_.push_back(obs);
    return Release();
  }
  if (obs.found) {
    recent_.push_back(obs);
    if (recent_.size() > 4) recent_.erase(recent_.begin());
    if (recent_.size() == 4 && std::abs(recent_[3].cy - recent_[0].cy) >= config_.min_move_px)
      windows_.push_back(recent_);
  } else {
    recent_.clear();
  }
  // Not moving yet, or only reporting: nothing is held.
  const bool hold = config_.apply && !windows_.empty();
  if (hold) held_.push_back(obs);
  if (static_cast<int>(windows_.size()) >= config_.min_windows) Decide(true);
  else if (static_cast<int>(held_.size()) >= config_.max_held) Decide(false);
  if (!hold) return {obs};
  return retiming_.decided ? Release() : std::vector<BallObservation>{};
}

std::vector<BallObservation> FrameRetimer::Flush() {
  if (!retiming_.decided) Decide(static_cast<int>(windows_.size()) >= config_.min_windows / 2);
  return Release();
}

void FrameRetimer::Decide(bool enough) {
  retiming_.decided = true;
  retiming_.windows = static_cast<int>(windows_.size());
  if (!uniform_) {
    retiming_.verdict = "frame times as stamped (not evenly spaced: the capture's own)";
    return;
  }
  if (!enough || period_s_ <= 0) {
    retiming_.verdict = "frame times as stamped (too little flight to test them)";
    return;
  }
  const auto median_for = [&](double f, double c) {
    std::vector<double> d;
    for (const auto& w : windows_) {
      double t[4], y[4];
      for (int k = 0; k < 4; ++k) {
        t[k] = f > 0 ? Tick(Seconds(w[k].utime), f, c) : Seconds(w[k].utime);
        y[k] = w[k].cy;
      }
      if (!(t[0] < t[1] && t[1] < t[2] && t[2] < t[3])) return 1e300;
      d.push_back(ThirdDifference(t, y));
    }
    return Median(d);
  };
  const double stamped_fps = 1 / period_s_;
  retiming_.median_as_stamped = median_for(0, 0);
  double best = 1e300, best_f = 0, best_c = 0;
  for (double f : kSourceFps) {
    const double ratio = f / stamped_fps;
    // Not faster, or a whole multiple (every n-th picture kept: evenly spaced anyway).
    if (ratio < 1.05 || std::abs(ratio - std::round(ratio)) < 0.01 * ratio) continue;
    // A broadcast rate (23.976 = 24/1.001) must fit clearly better than the round one next to it.
    const bool round = std::abs(f - std::round(f)) < 1e-6;
    for (int k = 0; k < 10; ++k) {
      const double m = median_for(f, 0.1 * k);
      if (m < best * (round ? 1.0 : 0.9)) best = m, best_f = f, best_c = 0.1 * k;
    }
  }
  retiming_.median_retimed = best;
  char line[320];
  if (best_f > 0 && best * config_.min_gain < retiming_.median_as_stamped) {
    retiming_.retimed = true;
    retiming_.source_fps = best_f;
    retiming_.phase = best_c;
    std::snprintf(line, sizeof line,
                  "%s: taken at %.4g fps and stamped at %.4g fps (pictures dropped); the ball's "
                  "flight fits the %.4g fps times %.1fx better (%d windows)%s",
                  config_.apply ? "frames re-timed" : "frame times as stamped, but they look",
                  best_f, stamped_fps, best_f, retiming_.median_as_stamped / best, retiming_.windows,
                  config_.apply ? "" : ": --retime-frames to read them at the times they were taken");
  } else {
    std::snprintf(line, sizeof line, "frame times as stamped (no faster source rate fits the flight %gx better; the best: %.1fx)",
                  config_.min_gain, best > 0 && best < 1e300 ? retiming_.median_as_stamped / best : 1.0);
  }
  retiming_.verdict = line;
}

BallObservation FrameRetimer::Applied(BallObservation o) const {
  if (!retiming_.retimed || !config_.apply) return o;
  const double t = Tick(Seconds(o.utime), retiming_.source_fps, retiming_.phase);
  o.utime = static_cast<int64_t>(std::llround(t * 1e6));
  return o;
}

std::vector<BallObservation> FrameRetimer::Release() {
  std::vector<BallObservation> out;
  for (const auto& o : held_) out.push_back(Applied(o));
  held_.clear();
  windows_.clear();
  recent_.clear();
  return out;
}

}  // namespace bouncefit
