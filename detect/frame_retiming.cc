#include "detect/frame_retiming.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

namespace bouncefit {

namespace {

// Round rates first (see the choice below).
constexpr double kSourceFps[] = {24, 25, 30, 48, 50, 60, 90, 100, 120, 23.976, 29.97, 59.94, 119.88};

double Seconds(int64_t utime) { return static_cast<double>(utime) * 1e-6; }

constexpr size_t kMinArcSamples = 5;  // a parabola (3 parameters) and 2 residuals at least

// Residual sum of squares of the least-squares parabola y(t) through the points, px^2.
double ParabolaRss(const std::vector<double>& t, const std::vector<double>& y) {
  const size_t n = t.size();
  double mean = 0;
  for (double v : t) mean += v / static_cast<double>(n);
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (size_t i = 0; i < n; ++i) {
    const double u = t[i] - mean;  // centred: a well-conditioned fit
    a.row(static_cast<Eigen::Index>(i)) << 1, u, u * u;
    b(static_cast<Eigen::Index>(i)) = y[i];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  return (a * x - b).squaredNorm();
}

}  // namespace

std::vector<BallObservation> FrameRetimer::Push(const BallObservation& obs) {
  if (last_utime_ >= 0) {
    const double dt = Seconds(obs.utime - last_utime_);
    if (period_s_ == 0) period_s_ = dt;
    if (dt <= 0 || std::abs(dt - period_s_) > config_.uniform_tolerance * period_s_) uniform_ = false;
  }
  last_utime_ = obs.utime;
  if (retiming_.decided) return {obs};
  if (!uniform_) {
    Decide(false);
    held_.push_back(obs);
    return Release();
  }
  if (obs.found) {
    if (moving_) {
      arc_.push_back(obs);
      // An impact: the height (image y, down) turned from falling to rising at the sample
      // before last. It belongs to neither arc.
      const size_t n = arc_.size();
      if (n >= 3 && arc_[n - 2].cy > arc_[n - 3].cy && arc_[n - 2].cy >= arc_[n - 1].cy) {
        const BallObservation after = arc_.back();
        arc_.resize(n - 2);
        CloseArc();
        arc_.push_back(after);
      }
    } else {
      recent_.push_back(obs);
      if (recent_.size() > 4) recent_.erase(recent_.begin());
      if (recent_.size() == 4 && std::abs(recent_[3].cy - recent_[0].cy) >= config_.min_move_px) {
        moving_ = true;
        arc_ = recent_;
      }
    }
  } else {
    recent_.clear();
    CloseArc();  // unseen: the arc cannot be followed across the gap
  }
  // Not moving yet, or only reporting: nothing is held.
  const bool hold = config_.mode != FrameTimes::kStamped && moving_;
  if (hold) held_.push_back(obs);
  if (Dof() >= config_.min_dof) Decide(true);
  else if (static_cast<int>(held_.size()) >= config_.max_held) Decide(false);
  if (!hold) return {obs};
  return retiming_.decided ? Release() : std::vector<BallObservation>{};
}

void FrameRetimer::CloseArc() {
  if (arc_.size() >= kMinArcSamples) arcs_.push_back(arc_);
  arc_.clear();
}

int FrameRetimer::Dof() const {
  int dof = 0;
  for (const auto& a : arcs_) dof += static_cast<int>(a.size()) - 3;
  if (arc_.size() >= kMinArcSamples) dof += static_cast<int>(arc_.size()) - 3;
  return dof;
}

std::vector<BallObservation> FrameRetimer::Flush() {
  if (!retiming_.decided) Decide(Dof() >= config_.min_dof / 2);
  return Release();
}

void FrameRetimer::Decide(bool enough) {
  retiming_.decided = true;
  CloseArc();
  retiming_.arcs = static_cast<int>(arcs_.size());
  if (!uniform_) {
    retiming_.verdict = "frame times as stamped (not evenly spaced: the capture's own)";
    return;
  }
  if (!enough || period_s_ <= 0) {
    retiming_.verdict = "frame times as stamped (too little flight to test them)";
    return;
  }
  // Pooled residual variance of the pieces' parabolas, px^2, on a clock (f = 0: the stamps),
  // every piece but `skip`.
  const auto variance_of = [&](const std::vector<std::vector<BallObservation>>& pieces, double f, double c,
                               size_t skip) {
    double rss = 0;
    int dof = 0;
    std::vector<double> t, y;
    for (size_t k = 0; k < pieces.size(); ++k) {
      if (k == skip) continue;
      t.clear();
      y.clear();
      for (const auto& o : pieces[k]) {
        t.push_back(f > 0 ? TakenAtSeconds(Seconds(o.utime), f, c) : Seconds(o.utime));
        y.push_back(o.cy);
        if (t.size() > 1 && !(t.back() > t[t.size() - 2])) return 1e300;  // two on one tick
      }
      rss += ParabolaRss(t, y);
      dof += static_cast<int>(pieces[k].size()) - 3;
    }
    return rss / std::max(dof, 1);
  };
  const size_t all = arcs_.size();
  const auto variance_for = [&](double f, double c) { return variance_of(arcs_, f, c, all); };
  const double stamped_fps = 1 / period_s_;
  retiming_.stamped_fps = stamped_fps;
  const double as_stamped = variance_for(0, 0);
  double best = 1e300, best_f = 0, best_c = 0;
  for (double f : kSourceFps) {
    const double ratio = f / stamped_fps;
    // Not faster, or a whole multiple (every n-th picture kept: evenly spaced anyway).
    if (ratio < 1.05 || std::abs(ratio - std::round(ratio)) < 0.01 * ratio) continue;
    // A broadcast rate (23.976 = 24/1.001) must fit clearly better than the round one next to it.
    const bool round = std::abs(f - std::round(f)) < 1e-6;
    for (int k = 0; k < 10; ++k) {
      const double v = variance_for(f, 0.1 * k);
      if (v < best * (round ? 1.0 : 0.9)) best = v, best_f = f, best_c = 0.1 * k;
    }
  }
  retiming_.rms_as_stamped_px = std::sqrt(as_stamped);
  retiming_.rms_retimed_px = best < 1e300 ? std::sqrt(best) : 0;
  // A perfect fit (no noise at all) on both clocks is no evidence either way.
  retiming_.gain = best > 0 && best < 1e300 ? as_stamped / best : (as_stamped > 0 && best == 0 ? 1e300 : 1.0);
  char line[360];
  const double explained_px = best < as_stamped ? std::sqrt(as_stamped - best) : 0;
  const auto convinces = [&](double stamped_v, double retimed_v) {
    return retimed_v < 1e300 && stamped_v >= config_.min_gain * retimed_v &&
           std::sqrt(std::max(0.0, stamped_v - retimed_v)) >= config_.min_explained_px;
  };
  // Dropped pictures misplace the ball in every arc they fall in; a smeared impact or a hand's
  // throw in one arc is no clock. The re-timing must convince with each piece of the flight
  // left out in turn (each arc, or the two halves of a lone arc): no one piece carries it.
  std::vector<std::vector<BallObservation>> pieces = arcs_;
  if (pieces.size() == 1) {
    const auto& a = arcs_.front();
    const auto half = a.begin() + static_cast<std::ptrdiff_t>(a.size() / 2);
    pieces = {std::vector<BallObservation>(a.begin(), half), std::vector<BallObservation>(half, a.end())};
  }
  int carried_by = -1;  // the piece without which the re-timing does not convince
  double without_stamped = 0, without_retimed = 0;
  if (best_f > 0 && retiming_.gain >= config_.min_gain && explained_px >= config_.min_explained_px) {
    for (size_t k = 0; k < pieces.size() && carried_by < 0; ++k) {
      const double vs = variance_of(pieces, 0, 0, k), vr = variance_of(pieces, best_f, best_c, k);
      if (!convinces(vs, vr)) carried_by = static_cast<int>(k), without_stamped = vs, without_retimed = vr;
    }
  }
  if (best_f > 0 && retiming_.gain >= config_.min_gain && explained_px >= config_.min_explained_px &&
      carried_by < 0) {
    retiming_.retimed = true;
    retiming_.applied = config_.mode == FrameTimes::kRetimed;
    retiming_.source_fps = best_f;
    retiming_.phase = best_c;
    std::snprintf(line, sizeof line,
                  "%s: taken at %.4g fps and stamped at %.4g fps (pictures dropped): the ball's "
                  "arcs fit the %.4g fps times with %.1f px of residual, %.1f px as stamped (%d arcs)",
                  retiming_.applied ? "frames re-timed" : "frame times as stamped (--keep-frame-times), but they look",
                  best_f, stamped_fps, best_f, retiming_.rms_retimed_px, retiming_.rms_as_stamped_px,
                  retiming_.arcs);
  } else if (carried_by >= 0) {
    std::snprintf(line, sizeof line,
                  "frame times as stamped (the %.4g fps times fit the ball's arcs with %.1f px of residual, "
                  "%.1f px as stamped, but only through one %s: without it %.1f px at %.4g fps, %.1f px as stamped)",
                  best_f, retiming_.rms_retimed_px, retiming_.rms_as_stamped_px,
                  arcs_.size() == 1 ? "half of its arc" : "arc",
                  without_retimed < 1e300 ? std::sqrt(without_retimed) : 0.0, best_f, std::sqrt(without_stamped));
  } else {
    std::snprintf(line, sizeof line,
                  "frame times as stamped (no faster source rate fits the ball's arcs by far better: "
                  "%.1f px of residual as stamped, %.1f px at best re-timed)",
                  retiming_.rms_as_stamped_px, retiming_.rms_retimed_px);
  }
  retiming_.verdict = line;
}

BallObservation FrameRetimer::Retimed(BallObservation o) const {
  if (!retiming_.retimed) return o;
  const double t = TakenAtSeconds(Seconds(o.utime), retiming_.source_fps, retiming_.phase);
  o.utime = static_cast<int64_t>(std::llround(t * 1e6));
  return o;
}

std::vector<BallObservation> FrameRetimer::Release() {
  std::vector<BallObservation> out;
  out.swap(held_);
  held_.clear();
  arcs_.clear();
  arc_.clear();
  recent_.clear();
  return out;
}

}  // namespace bouncefit
