// How a drop starts: a release from a seen hold, a fall whose release was missed, or an
// arc entered mid-flight (thrown, already bouncing).
#include "detect/bounce_detector.h"
#include "detect/detector_stats.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {

using detector_stats::LineDrift;
using detector_stats::Median;
using detector_stats::ParabolaAt;

bool BounceDetector::ReleasedFromHold(const Sample& s, std::vector<DetectorEvent>& ev) {
  const size_t n = hold_.size();
  if (n < 5) return false;
  const Sample& a = hold_[n - 2];
  const Sample& b = hold_[n - 1];
  std::vector<double> wt, wu, ww;
  for (size_t i = 0; i + 2 < n; ++i) {
    if (hold_[i].t < b.t - 0.5) continue;
    wt.push_back(hold_[i].t);
    wu.push_back(Down(hold_[i]));
    ww.push_back(Floor(hold_[i]));
  }
  if (wu.size() < 3) return false;
  const double ref_u = Median(wu), ref_w = Median(ww);
  const double thr = std::max(config_.release_px, Gate());
  auto still = [&](const Sample& q) {
    return std::abs(Down(q) - ref_u) <= thr && std::abs(Floor(q) - ref_w) <= thr;
  };
  // Held still: nearly every sample near the median (a stray detection is tolerated).
  size_t near = 0;
  double ss = 0;
  for (size_t i = 0; i < wu.size(); ++i) {
    if (std::abs(wu[i] - ref_u) > thr || std::abs(ww[i] - ref_w) > thr) continue;
    ++near;
    ss += (wu[i] - ref_u) * (wu[i] - ref_u);
  }
  if (static_cast<double>(near) < 0.9 * static_cast<double>(wu.size())) return false;
  // ... and not drifting: the first frames of a fall whose release was not seen are close
  // together too, but move the same way every frame. Taken for a hold they would make a
  // release arc held at the wrong place, and their spread the noise (gates a few times
  // too wide: a slow rebound then passes for more of the fall).
  if (std::abs(LineDrift(wt, wu)) > config_.max_hold_drift * thr) return false;
  if (!sigma_measured_)
    sigma_ = std::max(config_.noise_floor_px, std::sqrt(ss / static_cast<double>(near)));
  if (std::abs(Floor(a) - ref_w) > thr || std::abs(Floor(b) - ref_w) > thr) return false;
  const double da = Down(a) - ref_u, db = Down(b) - ref_u;
  if (!(db > thr && da > 0.5 * thr && db > da)) return false;

  // Released: the release arc is the end of the hold plus the samples moving down.
  Arc arc;
  arc.held = true;
  for (size_t i = 0; i + 2 < n; ++i)
    if (hold_[i].t >= a.t - config_.hold_window_s && still(hold_[i]))
      arc.samples.push_back(hold_[i]);
  arc.hold_samples = arc.samples.size();
  arc.samples.push_back(a);
  arc.samples.push_back(b);
  StartSequence(std::move(arc), s, ev);
  return true;
}

bool BounceDetector::FallFromUnseenRelease(const Sample& s, std::vector<DetectorEvent>& ev) {
  const auto m = static_cast<size_t>(config_.fall_start_samples);
  if (hold_.size() < m) return false;
  const std::vector<Sample> fall(hold_.end() - static_cast<long>(m), hold_.end());
  const double thr = std::max(config_.release_px, Gate());
  // Frame after frame, each a little further down the same vertical line than the last...
  for (size_t i = 1; i < m; ++i) {
    if (fall[i].t - fall[i - 1].t > 3 * frame_dt_) return false;
    if (std::abs(Floor(fall[i]) - Floor(fall[0])) > thr) return false;
    if (!(Down(fall[i]) > Down(fall[i - 1]))) return false;
  }
  // ... by more than a hold's jitter, faster and faster, smoothly (a parabola, not a hand).
  if (Down(fall.back()) - Down(fall.front()) < 2 * thr) return false;
  double rms = 0;
  const Eigen::Vector3d c = DownParabola(fall, &rms);
  if (!(c(2) > 0)) return false;
  if (rms > StartGate()) return false;
  // Far from its vertex already: it came from out of view, not from a hand (see below;
  // twice the margin: five samples place the vertex roughly).
  const double t_vertex = fall.back().t - c(1) / (2 * c(2));
  if (fall.front().t - t_vertex > 2 * UnseenReleaseMaxS(SlowdownOfBend(2 * c(2)))) return false;
  // Seen rising into its vertex (a clip begun just before a rebound's apex, which at 120 fps
  // stays within a hold's jitter for 6 frames): the top of an arc, not a fall from a release.
  // A vertex a frame or more before the first frame: whether the ball fell from a hand or
  // from its rise was never seen, and a release is bounce 0 only when it was
  // (ArcFromUnseenStart takes the arc). The vertex from the longest free flight the samples
  // show (five samples near a vertex place it roughly).
  double t_top = t_vertex;
  if (SeenRisingIntoFall(m, &t_top) || t_top < -frame_dt_) return false;
  // Seen rising into that vertex just before (a rebound, or a throw, entering the view): an
  // arc, not a fall from rest; ArcFromUnseenStart takes it with its rising branch.
  for (size_t i = hold_.size() - m, k = 0; i > 0 && k < 2; --i, ++k) {
    const Sample& before = hold_[i - 1];
    if (fall.front().t - before.t > 3 * frame_dt_) break;
    if (Down(before) > Down(fall.front()) + 2 * thr &&
        std::abs(Floor(before) - Floor(fall.front())) <= 10 * thr)
      return false;
  }

  // Released out of sight: a release arc from rest whose vertex is fitted, not seen.
  Arc arc;
  arc.held = false;
  arc.samples = fall;
  StartSequence(std::move(arc), s, ev);
  return true;
}

// How long before an entered arc the samples may show the impact it came from, s (its first
// samples after an impact at 20 fps, smeared, may not fit it: 0.2 s on the football).
constexpr double kBeforeEnteredArcS = 0.3;

bool BounceDetector::ArcFromUnseenStart(const Sample& s, std::vector<DetectorEvent>& ev) {
  auto m = static_cast<size_t>(config_.arc_start_samples);
  if (hold_.size() < m) return false;
  // At high frame rates a few samples show no bend: take at least 0.12 s.
  while (m < hold_.size() && hold_.back().t - hold_[hold_.size() - m - 1].t <= 0.12) ++m;
  std::vector<Sample> run(hold_.end() - static_cast<long>(m), hold_.end());
  for (size_t i = 1; i < m; ++i)
    if (run[i].t - run[i - 1].t > 3 * frame_dt_) return false;
  const double thr = std::max(config_.release_px, Gate());
  // A hand's hold before a throw is not on the arc: leading samples that barely move go.
  auto step = [](const Sample& p, const Sample& q) { return std::hypot(q.x - p.x, q.y - p.y); };
  while (run.size() > 4 && step(run[0], run[1]) < 0.3 * thr && step(run[1], run[2]) < 0.3 * thr)
    run.erase(run.begin());
  // The lowest sample of a V, fallen into and risen from, straddles an impact: it lies on the
  // fall or on the rebound. On the wrong one it bends a young arc's fit (a ping-pong ball
  // seen from mid-fall at 30 fps: gravity 38% high, the arc lost at its apex). Of the fits
  // with and without it, the one that bends nearer free fall at the ball's size is kept
  // (without it when the size is not known); a sample left out stays among those before the
  // arc (the impact it came from).
  const size_t first = hold_.size() - run.size();
  if (first >= 1 && run.size() >= 5 && run[0].t - hold_[first - 1].t <= 3 * frame_dt_ &&
      Down(hold_[first - 1]) < Down(run[0]) - thr && Down(run[1]) < Down(run[0]) - thr) {
    const std::vector<Sample> after(run.begin() + 1, run.end());
    const double with = 2 * DownParabola(run)(2), without = 2 * DownParabola(after)(2);
    // On the clock the file may have (a slow-motion file bends at g / k^2).
    const double k = without > 0 ? SlowdownOfBend(without) : 0;
    const double g_px = k > 0 ? SizeGravityPx() / (k * k) : 0;
    auto off = [&](double bend) { return bend > 0 ? std::abs(std::log(bend / g_px)) : 1e9; };
    if (!(g_px > 0) || off(without) < off(with)) run = after;
  }
  if (run.size() < static_cast<size_t>(config_.arc_start_samples)) return false;
  m = run.size();
  // Still at first, moving down at last: a release from a hold, which ReleasedFromHold
  // takes once the move is clear.
  if (std::hypot(run[1].x - run[0].x, run[1].y - run[0].y) < thr &&
      Down(run[m - 1]) > Down(run[m - 2]))
    return false;
  double path = 0;
  for (size_t i = 1; i < m; ++i)
    path += std::hypot(run[i].x - run[i - 1].x, run[i].y - run[i - 1].y);
  if (path < 3 * thr) return false;
  // One parabola in both image axes, bending down (the roll is not known yet: gravity may
  // lean a little sideways, a hand's path bends any way).
  const auto rows = static_cast<Eigen::Index>(m);
  Eigen::MatrixXd a(rows, 3);
  Eigen::MatrixXd b(rows, 2);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const Sample& q = run[static_cast<size_t>(i)];
    const double dt = q.t - run.back().t;
    a(i, 0) = 1;
    a(i, 1) = dt;
    a(i, 2) = dt * dt;
    b(i, 0) = Down(q);
    b(i, 1) = Floor(q);
  }
  const Eigen::MatrixXd c = a.colPivHouseholderQr().solve(b);
  const double span = run.back().t - run.front().t;
  // The bend must show: the parabola's sag over the run beyond the gate.
  if (!(c(2, 0) * span * span / 4 > Gate())) return false;
  if (std::abs(c(2, 1)) > 0.35 * c(2, 0)) return false;
  // A hand moves the ball along gentle curves too: with the ball's size known, the bend must
  // be free flight's on some clock the file may have (SlowdownOfBend).
  const double slowdown = SlowdownOfBend(2 * c(2, 0));
  if (!(slowdown > 0)) return false;
  const Eigen::MatrixXd r = a * c - b;
  const double rms_u = std::sqrt(r.col(0).squaredNorm() / static_cast<double>(m));
  const double rms_w = std::sqrt(r.col(1).squaredNorm() / static_cast<double>(m));
  if (rms_u > StartGate() || rms_w > StartGate()) return false;
  // Over a floor an earlier drop measured (its free fall, 15 frames or more), an arc whose
  // vertex is lower than any apex a drop reports, and not under the floor (by two radii at
  // most), is the ball settling after that drop (which ended at rest on such hops), not a new
  // drop: its few frames would only refit the scale to nonsense (a ping-pong ball's 2-3 cm
  // hops at 24 fps: 483 and then 77 px/m, and a false 4 cm row). A floor from a false start,
  // on the ball's size, is no such floor (a shaken copy of the green ball clip: 50 px above
  // the picture).
  const Calibration& known = calibration_.calibration;
  if (calibrated_ && known.has_floor && known.samples >= 15 &&
      known.FreeFallMeasured(config_.calibration.max_free_fall_rel_sigma)) {
    const double h = known.floor_centre_px() - (c(0, 0) - c(1, 0) * c(1, 0) / (4 * c(2, 0)));
    if (h < MinApexPx() && h > -2 * RadiusPx()) return false;
  }

  // Samples just before the run on its parabola are the arc's own (a rebound's rise near its
  // apex, left out as barely moving): where the arc was first seen decides how it began.
  const size_t seen = OnArcBefore(hold_.size() - m, c.col(0), c.col(1), run.back().t, thr);
  run.insert(run.begin(), hold_.end() - static_cast<long>(m + seen), hold_.end() - static_cast<long>(m));
  m = run.size();
  Arc arc;
  arc.samples = run;
  // A fall that starts at its vertex is a release out of sight (bounce 0 is its vertex), if
  // the camera was watching then.
  const double t_vertex = run.back().t - c(1, 0) / (2 * c(2, 0));
  if (t_vertex >= -frame_dt_ && t_vertex >= run.front().t - UnseenReleaseMaxS(slowdown) &&
      t_vertex <= run.front().t + 0.5 * frame_dt_) {
    StartSequence(std::move(arc), s, ev);
    return true;
  }
  arc.entered = true;
  // Its apex is bounce 0 when the ball came from the hand (seen before, not falling into
  // the arc), bounce 1 when it came from an impact or from out of view. Entered falling, its
  // apex never in view: the first apex seen, its rebound's, is bounce 1 (as a ball entered
  // rising has its first apex seen bounce 1).
  int first_bounce = t_vertex < run.front().t ? 0 : 1;
  const size_t before = hold_.size() - m;
  if (before >= 1 && run.front().t - hold_[before - 1].t <= 3 * frame_dt_) {
    // Only a sample where the arc leads back to can be the hand it left (a detection far off
    // it, say of a hand elsewhere in the picture, tells nothing of where the ball came from).
    // At the hand's time, roughly; or closely at some time before the arc's first sample (the
    // ball left the hand between the two: at 30 fps a throw's first frame may show it 17 px
    // up, and the hand's last one still where it held it).
    const Sample& hand = hold_[before - 1];
    auto passes = [&](double t, double tol) {
      const double dt = t - run.back().t;
      return std::abs(Down(hand) - ParabolaAt(c.col(0), dt)) <= tol &&
             std::abs(Floor(hand) - ParabolaAt(c.col(1), dt)) <= tol;
    };
    bool on_arc = passes(hand.t, std::max(4 * thr, 2 * RadiusPx()));
    for (int k = 1; k <= 8 && !on_arc; ++k)
      on_arc = passes(hand.t + (run.front().t - hand.t) * k / 8.0, 2 * thr);
    const bool falling_in = before >= 2 && Down(hold_[before - 1]) > Down(hold_[before - 2]) + thr;
    if (on_arc && !falling_in) first_bounce = 0;
  }
  // The lowest the ball was seen shortly before the arc: whether that was the floor is known
  // at the first impact (ConfirmImpact).
  std::optional<Sample> low;
  for (size_t k = before; k > 0 && run.front().t - hold_[k - 1].t <= kBeforeEnteredArcS; --k)
    if (!low || Down(hold_[k - 1]) > Down(*low)) low = hold_[k - 1];
  // The last sample before the arc, from the recent ones (in time order, the arc's own among
  // them): none ever when they are not yet as many as are kept, not known when all are the arc's.
  int64_t seen_before = seen_.size() < kSeenKept ? INT64_MIN : INT64_MAX;
  for (const Sample& q : seen_)
    if (q.t < run.front().t) seen_before = q.utime;
  StartSequence(std::move(arc), s, ev);
  first_bounce_ = first_bounce;
  low_before_entered_ = low;
  seen_before_entered_utime_ = seen_before;
  return true;
}

bool BounceDetector::EnteredFallWasAnUnseenRelease() const {
  const int width = config_.image_width_px, height = config_.image_height_px;
  if (!(width > 0 && height > 0) || arcs_.empty() || !calibrated_) return false;
  const Arc& a = arcs_[0];
  if (!a.entered || !a.fit_ok || low_before_entered_) return false;
  const FlightGlobals& g = calibration_.flight.globals;
  const double t_vertex = a.fit.t_apex, late = a.samples.front().t - t_vertex;
  // First seen after its vertex, before the ball could have fallen four radii and been
  // noticed two frames later (a still ball is found once it has moved about its size).
  const double r = RadiusPx();
  if (!(late > 0) || !(g.gravity_px > 0) ||
      late > std::sqrt(2 * 4 * r / g.gravity_px) + 2 * frame_dt_)
    return false;
  // Its vertex in the picture, the whole ball (one entered from above had it out of view).
  double x = 0, y = 0;
  FlightPosition(g, a.fit, false, t_vertex, &x, &y);
  if (x < r || y < r || x > width - r || y > height - r) return false;
  // Rising into that vertex, it would have passed where it was first seen falling, as fast,
  // `late` before it: the camera watched then, three frames at least, and saw nothing.
  const double mirror_from = t_vertex - late - 3 * frame_dt_;
  return mirror_from >= 0 && seen_before_entered_utime_ < ToUtime(mirror_from);
}

bool BounceDetector::EnteredApexSeen() const {
  if (arcs_.empty() || !arcs_[0].entered || !arcs_[0].fit_ok) return false;
  const Arc& a = arcs_[0];
  return a.fit.t_apex >= a.samples.front().t && a.fit.t_apex <= a.samples.back().t;
}

void BounceDetector::StartSequence(Arc release, const Sample& s, std::vector<DetectorEvent>& ev) {
  release.release = !release.entered;
  first_bounce_ = 0;
  low_before_entered_.reset();
  seen_before_entered_utime_ = INT64_MAX;
  hold_.clear();
  arcs_.clear();
  arcs_.push_back(std::move(release));
  pending_up_.clear();
  pending_off_.clear();
  peaks_.clear();
  impacts_.clear();
  bounce0_emitted_ = false;
  ++sequence_;
  phase_ = Phase::kFlight;
  if (calibrated_) {
    RefitArc(arcs_[0]);
    // Scale and floor known from an earlier drop: the release height is known now.
    if (arcs_[0].release && calibration_.calibration.valid() &&
        calibration_.calibration.has_floor) {
      EmitPeak(0, s.utime, ev);
      bounce0_emitted_ = true;
    }
  }
}

size_t BounceDetector::OnArcBefore(size_t first, const Eigen::Vector3d& cu,
                                  const Eigen::Vector3d& cw, double t_ref, double tol) const {
  size_t seen = 0;
  double next_t = first < hold_.size() ? hold_[first].t : 0;
  for (size_t i = std::min(first, hold_.size()); i > 0; --i) {
    const Sample& q = hold_[i - 1];
    const double dt = q.t - t_ref;
    if (next_t - q.t > 3 * frame_dt_ || std::abs(Down(q) - ParabolaAt(cu, dt)) > tol ||
        std::abs(Floor(q) - ParabolaAt(cw, dt)) > tol)
      break;
    ++seen;
    next_t = q.t;
  }
  return seen;
}

bool BounceDetector::SeenRisingIntoFall(size_t m, double* t_vertex) const {
  // The samples before the fall, back to back, over half a second at most.
  size_t from = hold_.size() - m;
  while (from > 0 && hold_[from].t - hold_[from - 1].t <= 3 * frame_dt_ &&
         hold_.back().t - hold_[from - 1].t <= 0.5)
    --from;
  const double thr = std::max(config_.release_px, Gate());
  // The longest run of them that ends with the fall and is one free flight ...
  for (size_t f = from; f + m + 2 <= hold_.size(); ++f) {
    const std::vector<Sample> run(hold_.begin() + static_cast<long>(f), hold_.end());
    double rms = 0;
    const Eigen::Vector3d c = DownParabola(run, &rms);
    if (!(c(2) > 0) || rms > StartGate() || !(SlowdownOfBend(2 * c(2)) > 0)) continue;
    // ... began lower than its top, beyond a hold's jitter: the ball rose into the vertex.
    *t_vertex = run.back().t - c(1) / (2 * c(2));
    double top = Down(run.front());
    for (const Sample& q : run) top = std::min(top, Down(q));
    return run.front().t < *t_vertex && Down(run.front()) - top > thr + 2 * rms;
  }
  return false;
}

Eigen::Vector3d BounceDetector::DownParabola(const std::vector<Sample>& run, double* rms) const {
  const auto rows = static_cast<Eigen::Index>(run.size());
  Eigen::MatrixXd a(rows, 3);
  Eigen::VectorXd b(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const double dt = run[static_cast<size_t>(i)].t - run.back().t;
    a(i, 0) = 1;
    a(i, 1) = dt;
    a(i, 2) = dt * dt;
    b(i) = Down(run[static_cast<size_t>(i)]);
  }
  const Eigen::Vector3d c = a.colPivHouseholderQr().solve(b);
  if (rms) *rms = std::sqrt((a * c - b).squaredNorm() / static_cast<double>(rows));
  return c;
}

}  // namespace bouncefit
