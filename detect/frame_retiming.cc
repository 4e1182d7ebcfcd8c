#include "detect/frame_retiming.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

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
  if (CentrePlaced(obs)) {
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
  // Pooled residual variance of the pieces' parabolas, px^2, on a clock (f = 0: the stamps).
  const auto variance_of = [&](const std::vector<std::vector<BallObservation>>& pieces, double f, double c) {
    double rss = 0;
    int dof = 0;
    std::vector<double> t, y;
    for (const auto& piece : pieces) {
      t.clear();
      y.clear();
      for (const auto& o : piece) {
        t.push_back(f > 0 ? TakenAtSeconds(Seconds(o.utime), f, c) : Seconds(o.utime));
        y.push_back(o.cy);
        if (t.size() > 1 && !(t.back() > t[t.size() - 2])) return 1e300;  // two on one tick
      }
      rss += ParabolaRss(t, y);
      dof += static_cast<int>(piece.size()) - 3;
    }
    return rss / std::max(dof, 1);
  };
  const auto variance_for = [&](double f, double c) { return variance_of(arcs_, f, c); };
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
  const double explained_px = best < as_stamped ? std::sqrt(as_stamped - best) : 0;
  // Dropped pictures misplace the ball all along an arc; a ball smeared over an impact, a
  // release or a hand misplace it at the arc's ends, where among 130 re-timings one absorbs
  // much of it. The re-timing must convince on the arcs' interior too: each arc without its
  // first and last samples.
  std::vector<std::vector<BallObservation>> interior;
  for (const auto& a : arcs_)
    if (a.size() >= 6) interior.emplace_back(a.begin() + 1, a.end() - 1);
  const double interior_stamped = interior.empty() ? 0 : variance_of(interior, 0, 0);
  const double interior_retimed = interior.empty() ? 1e300 : variance_of(interior, best_f, best_c);
  const bool interior_convinces =
      interior_retimed < 1e300 && interior_stamped >= config_.min_gain * interior_retimed &&
      std::sqrt(std::max(0.0, interior_stamped - interior_retimed)) >= config_.min_explained_px;
  const bool pooled_convinces =
      best_f > 0 && retiming_.gain >= config_.min_gain && explained_px >= config_.min_explained_px;
  if (pooled_convinces && interior_convinces) {
    retiming_.retimed = true;
    retiming_.applied = config_.mode == FrameTimes::kRetimed;
    retiming_.source_fps = best_f;
    retiming_.phase = best_c;
    retiming_.verdict = fmt::format(
        "{}: taken at {:.4g} fps and stamped at {:.4g} fps (pictures dropped): the ball's "
        "arcs fit the {:.4g} fps times with {:.1f} px of residual, {:.1f} px as stamped ({} arcs)",
        retiming_.applied ? "frames re-timed" : "frame times as stamped (--keep-frame-times), but they look",
        best_f, stamped_fps, best_f, retiming_.rms_retimed_px, retiming_.rms_as_stamped_px,
        retiming_.arcs);
  } else if (pooled_convinces) {
    retiming_.verdict = fmt::format(
        "frame times as stamped (the {:.4g} fps times fit the ball's arcs with {:.1f} px of residual, "
        "{:.1f} px as stamped, but only at their ends: inside them {:.1f} px at {:.4g} fps, {:.1f} px as stamped)",
        best_f, retiming_.rms_retimed_px, retiming_.rms_as_stamped_px,
        interior_retimed < 1e300 ? std::sqrt(interior_retimed) : 0.0, best_f, std::sqrt(interior_stamped));
  } else {
    retiming_.verdict = fmt::format(
        "frame times as stamped (no faster source rate fits the ball's arcs by far better: "
        "{:.1f} px of residual as stamped, {:.1f} px at best re-timed)",
        retiming_.rms_as_stamped_px, retiming_.rms_retimed_px);
  }
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
