// How a drop starts: a release from a seen hold, a fall whose release was missed, or an
// arc entered mid-flight (thrown, already bouncing); and the waiting after a drop at rest.
#include "detect/drop_start.h"
#include "detect/detector_stats.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace bouncefit {

using detector_stats::LineDrift;
using detector_stats::Median;
using detector_stats::ParabolaAt;

DropStart::DropStart(const DropStartConfig& config, DetectorScene& scene)
    : config_(config), scene_(scene) {}

DropStartFound DropStart::Found(DetectorArc arc, int first_bounce,
                                std::optional<DetectorSample> low_before,
                                int64_t seen_before_utime) {
  hold_.clear();
  low_before_entered_ = low_before;
  seen_before_entered_utime_ = seen_before_utime;
  DropStartFound found;
  found.arc = std::move(arc);
  found.first_bounce = first_bounce;
  return found;
}

void DropStart::ForgetStaleHold(double t, double lost_s) {
  if (!hold_.empty() && t - hold_.back().t > lost_s) hold_.clear();
}

void DropStart::Reset() {
  hold_.clear();
  rest_samples_.clear();
  rest_moves_ = 0;
}

void DropStart::RescaleTime(double k) {
  for (auto& q : hold_) q.t *= k;
  for (auto& q : rest_samples_) q.t *= k;
}

bool DropStart::EnteredFromTheFloor() const {
  const Calibration& cal = scene_.calibration().calibration;
  return low_before_entered_ && scene_.calibrated() && cal.has_floor &&
         cal.floor_centre_px() - Down(*low_before_entered_) <=
             std::max(2 * scene_.RadiusPx(), 3 * scene_.Gate());
}

std::optional<DropStartFound> DropStart::ReleasedFromHold() {
  const size_t n = hold_.size();
  if (n < 5) return std::nullopt;
  const DetectorSample& a = hold_[n - 2];
  const DetectorSample& b = hold_[n - 1];
  std::vector<double> wt, wu, ww;
  for (size_t i = 0; i + 2 < n; ++i) {
    if (hold_[i].t < b.t - 0.5) continue;
    wt.push_back(hold_[i].t);
    wu.push_back(Down(hold_[i]));
    ww.push_back(Floor(hold_[i]));
  }
  if (wu.size() < 3) return std::nullopt;
  const double ref_u = Median(wu), ref_w = Median(ww);
  const double thr = std::max(config_.release_px, scene_.Gate());
  auto still = [&](const DetectorSample& q) {
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
  if (static_cast<double>(near) < 0.9 * static_cast<double>(wu.size())) return std::nullopt;
  // ... and not drifting: the first frames of a fall whose release was not seen are close
  // together too, but move the same way every frame. Taken for a hold they would make a
  // release arc held at the wrong place, and their spread the noise (gates a few times
  // too wide: a slow rebound then passes for more of the fall).
  if (std::abs(LineDrift(wt, wu)) > config_.max_hold_drift * thr) return std::nullopt;
  scene_.TakeHoldNoise(std::sqrt(ss / static_cast<double>(near)));
  if (std::abs(Floor(a) - ref_w) > thr || std::abs(Floor(b) - ref_w) > thr) return std::nullopt;
  const double da = Down(a) - ref_u, db = Down(b) - ref_u;
  if (!(db > thr && da > 0.5 * thr && db > da)) return std::nullopt;

  // Released: the release arc is the end of the hold plus the samples moving down.
  DetectorArc arc;
  arc.held = true;
  for (size_t i = 0; i + 2 < n; ++i)
    if (hold_[i].t >= a.t - config_.hold_window_s && still(hold_[i]))
      arc.samples.push_back(hold_[i]);
  arc.hold_samples = arc.samples.size();
  arc.samples.push_back(a);
  arc.samples.push_back(b);
  return Found(std::move(arc));
}

std::optional<DropStartFound> DropStart::FallFromUnseenRelease() {
  const auto m = static_cast<size_t>(config_.fall_start_samples);
  if (hold_.size() < m) return std::nullopt;
  const std::vector<DetectorSample> fall(hold_.end() - static_cast<long>(m), hold_.end());
  const double thr = std::max(config_.release_px, scene_.Gate());
  // Frame after frame, each a little further down the same vertical line than the last...
  for (size_t i = 1; i < m; ++i) {
    if (fall[i].t - fall[i - 1].t > 3 * scene_.frame_dt()) return std::nullopt;
    if (std::abs(Floor(fall[i]) - Floor(fall[0])) > thr) return std::nullopt;
    if (!(Down(fall[i]) > Down(fall[i - 1]))) return std::nullopt;
  }
  // ... by more than a hold's jitter, faster and faster, smoothly (a parabola, not a hand).
  if (Down(fall.back()) - Down(fall.front()) < 2 * thr) return std::nullopt;
  double rms = 0;
  const Eigen::Vector3d c = scene_.DownParabola(fall, &rms);
  if (!(c(2) > 0)) return std::nullopt;
  if (rms > scene_.StartGate()) return std::nullopt;
  // Far from its vertex already: it came from out of view, not from a hand (see below;
  // twice the margin: five samples place the vertex roughly).
  const double t_vertex = fall.back().t - c(1) / (2 * c(2));
  if (fall.front().t - t_vertex > 2 * UnseenReleaseMaxS(scene_.SlowdownOfBend(2 * c(2)))) return std::nullopt;
  // Seen rising into its vertex (a clip begun just before a rebound's apex, which at 120 fps
  // stays within a hold's jitter for 6 frames): the top of an arc, not a fall from a release.
  // A vertex a frame or more before the first frame: whether the ball fell from a hand or
  // from its rise was never seen, and a release is bounce 0 only when it was
  // (ArcFromUnseenStart takes the arc). The vertex from the longest free flight the samples
  // show (five samples near a vertex place it roughly).
  double t_top = t_vertex;
  if (SeenRisingIntoFall(m, &t_top) || t_top < -scene_.frame_dt()) return std::nullopt;
  // Seen rising into that vertex just before (a rebound, or a throw, entering the view): an
  // arc, not a fall from rest; ArcFromUnseenStart takes it with its rising branch.
  for (size_t i = hold_.size() - m, k = 0; i > 0 && k < 2; --i, ++k) {
    const DetectorSample& before = hold_[i - 1];
    if (fall.front().t - before.t > 3 * scene_.frame_dt()) break;
    if (Down(before) > Down(fall.front()) + 2 * thr &&
        std::abs(Floor(before) - Floor(fall.front())) <= 10 * thr)
      return std::nullopt;
  }

  // Released out of sight: a release arc from rest whose vertex is fitted, not seen.
  DetectorArc arc;
  arc.held = false;
  arc.samples = fall;
  return Found(std::move(arc));
}

// How long before an entered arc the samples may show the impact it came from, s (its first
// samples after an impact at 20 fps, smeared, may not fit it: 0.2 s on the football).
constexpr double kBeforeEnteredArcS = 0.3;

std::optional<DropStartFound> DropStart::ArcFromUnseenStart() {
  auto m = static_cast<size_t>(config_.arc_start_samples);
  if (hold_.size() < m) return std::nullopt;
  // At high frame rates a few samples show no bend: take at least 0.12 s.
  while (m < hold_.size() && hold_.back().t - hold_[hold_.size() - m - 1].t <= 0.12) ++m;
  std::vector<DetectorSample> run(hold_.end() - static_cast<long>(m), hold_.end());
  for (size_t i = 1; i < m; ++i)
    if (run[i].t - run[i - 1].t > 3 * scene_.frame_dt()) return std::nullopt;
  const double thr = std::max(config_.release_px, scene_.Gate());
  // A hand's hold before a throw is not on the arc: leading samples that barely move go.
  auto step = [](const DetectorSample& p, const DetectorSample& q) { return std::hypot(q.x - p.x, q.y - p.y); };
  while (run.size() > 4 && step(run[0], run[1]) < 0.3 * thr && step(run[1], run[2]) < 0.3 * thr)
    run.erase(run.begin());
  // The lowest sample of a V, fallen into and risen from, straddles an impact: it lies on the
  // fall or on the rebound. On the wrong one it bends a young arc's fit (a ping-pong ball
  // seen from mid-fall at 30 fps: gravity 38% high, the arc lost at its apex). Of the fits
  // with and without it, the one that bends nearer free fall at the ball's size is kept
  // (without it when the size is not known); a sample left out stays among those before the
  // arc (the impact it came from).
  const size_t first = hold_.size() - run.size();
  if (first >= 1 && run.size() >= 5 && run[0].t - hold_[first - 1].t <= 3 * scene_.frame_dt() &&
      Down(hold_[first - 1]) < Down(run[0]) - thr && Down(run[1]) < Down(run[0]) - thr) {
    const std::vector<DetectorSample> after(run.begin() + 1, run.end());
    const double with = 2 * scene_.DownParabola(run)(2), without = 2 * scene_.DownParabola(after)(2);
    // On the clock the file may have (a slow-motion file bends at g / k^2).
    const double k = without > 0 ? scene_.SlowdownOfBend(without) : 0;
    const double g_px = k > 0 ? scene_.SizeGravityPx() / (k * k) : 0;
    auto off = [&](double bend) { return bend > 0 ? std::abs(std::log(bend / g_px)) : 1e9; };
    if (!(g_px > 0) || off(without) < off(with)) run = after;
  }
  if (run.size() < static_cast<size_t>(config_.arc_start_samples)) return std::nullopt;
  m = run.size();
  // Still at first, moving down at last: a release from a hold, which ReleasedFromHold
  // takes once the move is clear; unless the ball rose into that first sample just before
  // (the top of an arc is still for a few frames, a hold for longer).
  auto rose_into_run = [&] {
    for (size_t i = hold_.size() - m; i > 0 && run[0].t - hold_[i - 1].t <= 0.15; --i)
      if (Down(hold_[i - 1]) > Down(run[0]) + 2 * thr) return true;
    return false;
  };
  if (std::hypot(run[1].x - run[0].x, run[1].y - run[0].y) < thr &&
      Down(run[m - 1]) > Down(run[m - 2]) && !rose_into_run())
    return std::nullopt;
  double path = 0;
  for (size_t i = 1; i < m; ++i)
    path += std::hypot(run[i].x - run[i - 1].x, run[i].y - run[i - 1].y);
  if (path < 3 * thr) return std::nullopt;
  // One parabola in both image axes, bending down (the roll is not known yet: gravity may
  // lean a little sideways, a hand's path bends any way).
  Eigen::MatrixXd a, b;
  // Down and Floor of the run's samples as parabolas in dt from its last sample (one column each).
  auto fit = [&]() -> Eigen::MatrixXd {
    const auto rows = static_cast<Eigen::Index>(run.size());
    a.resize(rows, 3);
    b.resize(rows, 2);
    for (Eigen::Index i = 0; i < rows; ++i) {
      const DetectorSample& q = run[static_cast<size_t>(i)];
      const double dt = q.t - run.back().t;
      a(i, 0) = 1;
      a(i, 1) = dt;
      a(i, 2) = dt * dt;
      b(i, 0) = Down(q);
      b(i, 1) = Floor(q);
    }
    return a.colPivHouseholderQr().solve(b);
  };
  Eigen::MatrixXd c = fit();
  const double span = run.back().t - run.front().t;
  // The bend must show: the parabola's sag over the run beyond the gate.
  if (!(c(2, 0) * span * span / 4 > scene_.Gate())) return std::nullopt;
  if (std::abs(c(2, 1)) > 0.35 * c(2, 0)) return std::nullopt;
  // The lock waits for the ball seen falling from the highest it rose, by more than the gate
  // twice: a hand's lift slows into a hold as a rising throw slows into its vertex, but only
  // a flight falls on from there.
  double top = Down(run.front());
  for (const DetectorSample& q : run) top = std::min(top, Down(q));
  if (!(Down(run.back()) - top > 2 * scene_.Gate())) return std::nullopt;
  // A hand moves the ball along gentle curves too: with the ball's size known, the bend must
  // be free flight's on some clock the file may have (SlowdownOfBend).
  const double slowdown = scene_.SlowdownOfBend(2 * c(2, 0));
  if (!(slowdown > 0)) return std::nullopt;
  const Eigen::MatrixXd r = a * c - b;
  const double rms_u = std::sqrt(r.col(0).squaredNorm() / static_cast<double>(m));
  const double rms_w = std::sqrt(r.col(1).squaredNorm() / static_cast<double>(m));
  if (rms_u > scene_.StartGate() || rms_w > scene_.StartGate()) return std::nullopt;
  // Over a floor an earlier drop measured (its free fall, 15 frames or more), an arc whose
  // vertex is lower than any apex a drop reports, and not under the floor (by two radii at
  // most), is the ball settling after that drop (which ended at rest on such hops), not a new
  // drop: its few frames would only refit the scale to nonsense (a ping-pong ball's 2-3 cm
  // hops at 24 fps: 483 and then 77 px/m, and a false 4 cm row). A floor from a false start,
  // on the ball's size, is no such floor (a shaken copy of the green ball clip: 50 px above
  // the picture).
  const Calibration& known = scene_.calibration().calibration;
  if (scene_.calibrated() && known.has_floor && known.samples >= 15 &&
      known.FreeFallMeasured(scene_.calibrator().config().max_free_fall_rel_sigma)) {
    const double h = known.floor_centre_px() - (c(0, 0) - c(1, 0) * c(1, 0) / (4 * c(2, 0)));
    if (h < scene_.MinApexPx() && h > -2 * scene_.RadiusPx()) return std::nullopt;
  }

  // Samples just before the run on its parabola are the arc's own (a rebound's rise near its
  // apex, left out as barely moving): where the arc was first seen decides how it began.
  // A lock that waited for the fall reaches back along the arc, refitted as it grows (its fall
  // alone extrapolates its rise poorly).
  for (size_t seen = 1; seen > 0;) {
    seen = OnArcBefore(hold_.size() - m, c.col(0), c.col(1), run.back().t, thr);
    run.insert(run.begin(), hold_.end() - static_cast<long>(m + seen), hold_.end() - static_cast<long>(m));
    m = run.size();
    if (seen > 0) c = fit();
  }
  DetectorArc arc;
  arc.samples = run;
  // A fall that starts at its vertex is a release out of sight (bounce 0 is its vertex), if
  // the camera was watching then.
  const double t_vertex = run.back().t - c(1, 0) / (2 * c(2, 0));
  if (t_vertex >= -scene_.frame_dt() && t_vertex >= run.front().t - UnseenReleaseMaxS(slowdown) &&
      t_vertex <= run.front().t + 0.5 * scene_.frame_dt()) {
    return Found(std::move(arc));
  }
  arc.entered = true;
  // Its apex is bounce 0 when the ball came from the hand (seen before, not falling into
  // the arc), bounce 1 when it came from an impact or from out of view. Entered falling, its
  // apex never in view: the first apex seen, its rebound's, is bounce 1 (as a ball entered
  // rising has its first apex seen bounce 1).
  int first_bounce = t_vertex < run.front().t ? 0 : 1;
  const size_t before = hold_.size() - m;
  if (before >= 1 && run.front().t - hold_[before - 1].t <= 3 * scene_.frame_dt()) {
    // Only a sample where the arc leads back to can be the hand it left (a detection far off
    // it, say of a hand elsewhere in the picture, tells nothing of where the ball came from).
    // At the hand's time, roughly; or closely at some time before the arc's first sample (the
    // ball left the hand between the two: at 30 fps a throw's first frame may show it 17 px
    // up, and the hand's last one still where it held it).
    const DetectorSample& hand = hold_[before - 1];
    auto passes = [&](double t, double tol) {
      const double dt = t - run.back().t;
      return std::abs(Down(hand) - ParabolaAt(c.col(0), dt)) <= tol &&
             std::abs(Floor(hand) - ParabolaAt(c.col(1), dt)) <= tol;
    };
    bool on_arc = passes(hand.t, std::max(4 * thr, 2 * scene_.RadiusPx()));
    for (int k = 1; k <= 8 && !on_arc; ++k)
      on_arc = passes(hand.t + (run.front().t - hand.t) * k / 8.0, 2 * thr);
    const bool falling_in = before >= 2 && Down(hold_[before - 1]) > Down(hold_[before - 2]) + thr;
    if (on_arc && !falling_in) first_bounce = 0;
  }
  // The lowest the ball was seen shortly before the arc: whether that was the floor is known
  // at the first impact (ConfirmImpact).
  std::optional<DetectorSample> low;
  for (size_t k = before; k > 0 && run.front().t - hold_[k - 1].t <= kBeforeEnteredArcS; --k)
    if (!low || Down(hold_[k - 1]) > Down(*low)) low = hold_[k - 1];
  // The last sample before the arc, from the recent ones (in time order, the arc's own among
  // them): none ever when they are not yet as many as are kept, not known when all are the arc's.
  int64_t seen_before = scene_.seen().size() < DetectorScene::kSeenKept ? INT64_MIN : INT64_MAX;
  for (const DetectorSample& q : scene_.seen())
    if (q.t < run.front().t) seen_before = q.utime;
  return Found(std::move(arc), first_bounce, low, seen_before);
}

bool DropStart::EnteredFallWasAnUnseenRelease(const DetectorArc& first) const {
  const int width = config_.image_width_px, height = config_.image_height_px;
  if (!(width > 0 && height > 0) || !scene_.calibrated()) return false;
  const DetectorArc& a = first;
  if (!a.entered || !a.fit_ok || low_before_entered_) return false;
  const FlightGlobals& g = scene_.calibration().flight.globals;
  const double t_vertex = a.fit.t_apex, late = a.samples.front().t - t_vertex;
  // First seen after its vertex, before the ball could have fallen four radii and been
  // noticed two frames later (a still ball is found once it has moved about its size).
  const double r = scene_.RadiusPx();
  if (!(late > 0) || !(g.gravity_px > 0) ||
      late > std::sqrt(2 * 4 * r / g.gravity_px) + 2 * scene_.frame_dt())
    return false;
  // Its vertex in the picture, the whole ball (one entered from above had it out of view).
  double x = 0, y = 0;
  FlightPosition(g, a.fit, false, t_vertex, &x, &y);
  if (x < r || y < r || x > width - r || y > height - r) return false;
  // Rising into that vertex, it would have passed where it was first seen falling, as fast,
  // `late` before it: the camera watched then, three frames at least, and saw nothing.
  const double mirror_from = t_vertex - late - 3 * scene_.frame_dt();
  return mirror_from >= 0 && seen_before_entered_utime_ < scene_.ToUtime(mirror_from);
}

size_t DropStart::OnArcBefore(size_t first, const Eigen::Vector3d& cu,
                              const Eigen::Vector3d& cw, double t_ref, double tol) const {
  size_t seen = 0;
  for (size_t i = std::min(first, hold_.size()); i > 0; --i) {
    const DetectorSample& q = hold_[i - 1];
    const double dt = q.t - t_ref;
    // Across a gap the arc spent above the picture, its rise before it left: the fit reaches
    // it over the gap, to within the start's gate.
    double reach = tol;
    if (i < hold_.size() && hold_[i].t - q.t > 3 * scene_.frame_dt()) {
      if (!AboveTheTopBetween(q, hold_[i], cu, t_ref)) break;
      reach = std::max(tol, scene_.StartGate());
    }
    if (std::abs(Down(q) - ParabolaAt(cu, dt)) > reach || std::abs(Floor(q) - ParabolaAt(cw, dt)) > reach) break;
    ++seen;
  }
  return seen;
}

bool DropStart::AboveTheTopBetween(const DetectorSample& a, const DetectorSample& b, const Eigen::Vector3d& cu,
                                   double t_ref) const {
  // Image y from Down: the roll's share of Down, nearly the same at both ends of a gap in a
  // flight that rose and fell on one line.
  const double lean = 0.5 * (Down(a) - a.y + Down(b) - b.y);
  const double y_mid = ParabolaAt(cu, 0.5 * (a.t + b.t) - t_ref) - lean;
  return y_mid < std::max(a.r, b.r);
}

bool DropStart::SeenRisingIntoFall(size_t m, double* t_vertex) const {
  // The samples before the fall, back to back, over half a second at most; and across a gap
  // the fall's parabola spent above the picture (a rise out of its top, the fall back in),
  // half a second besides the gap.
  const std::vector<DetectorSample> fall(hold_.end() - static_cast<long>(m), hold_.end());
  const Eigen::Vector3d cu = scene_.DownParabola(fall);
  size_t from = hold_.size() - m;
  double gaps = 0;
  while (from > 0) {
    const double gap = hold_[from].t - hold_[from - 1].t;
    if (gap > 3 * scene_.frame_dt()) {
      if (gaps > 0 || !AboveTheTopBetween(hold_[from - 1], hold_[from], cu, fall.back().t)) break;
      gaps = gap;
    }
    if (hold_.back().t - hold_[from - 1].t > 0.5 + gaps) break;
    --from;
  }
  const double thr = std::max(config_.release_px, scene_.Gate());
  // The longest run of them that ends with the fall and is one free flight ...
  for (size_t f = from; f + m + 2 <= hold_.size(); ++f) {
    const std::vector<DetectorSample> run(hold_.begin() + static_cast<long>(f), hold_.end());
    double rms = 0;
    const Eigen::Vector3d c = scene_.DownParabola(run, &rms);
    if (!(c(2) > 0) || rms > scene_.StartGate() || !(scene_.SlowdownOfBend(2 * c(2)) > 0)) continue;
    // ... began lower than its top, beyond a hold's jitter: the ball rose into the vertex.
    *t_vertex = run.back().t - c(1) / (2 * c(2));
    double top = Down(run.front());
    for (const DetectorSample& q : run) top = std::min(top, Down(q));
    return run.front().t < *t_vertex && Down(run.front()) - top > thr + 2 * rms;
  }
  return false;
}

double DropStart::UnseenReleaseMaxS(double bend_slowdown) const {
  // Before the clock is decided a slowed file's seconds may be `slow-down` times too long.
  const double slow =
      scene_.clock_decided() ? 1.0 : std::max(scene_.config().capture_slowdown_hint, bend_slowdown);
  return std::max(config_.unseen_release_max_s * slow, 2 * scene_.frame_dt());
}

std::optional<DropStartFound> DropStart::OnWaiting(const DetectorSample& s) {
  hold_.push_back(s);
  while (!hold_.empty() && hold_.front().t < s.t - 1.0) hold_.erase(hold_.begin());
  if (auto found = ReleasedFromHold()) return found;
  if (auto found = FallFromUnseenRelease()) return found;
  return ArcFromUnseenStart();
}

bool DropStart::PickedUp(const DetectorSample& s) {
  const double thr = std::max(config_.release_px, scene_.Gate());
  if (rest_samples_.empty()) {
    rest_samples_.push_back(s);
    return false;
  }
  std::vector<double> ru, rw;
  for (const auto& r : rest_samples_) {
    ru.push_back(Down(r));
    rw.push_back(Floor(r));
  }
  const bool moved =
      std::abs(Down(s) - Median(ru)) > thr || std::abs(Floor(s) - Median(rw)) > thr;
  if (!moved) {
    rest_moves_ = 0;
    if (rest_samples_.size() < 30) rest_samples_.push_back(s);
    return false;
  }
  if (++rest_moves_ >= 3) {
    // Picked up (or kicked): wait for the next hold and release.
    hold_.clear();
    rest_samples_.clear();
    rest_moves_ = 0;
    return true;
  }
  return false;
}

}  // namespace bouncefit
