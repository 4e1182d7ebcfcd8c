#include "detect/bounce_detector.h"

#include "model/arc_apex.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {
namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// How far a least-squares line through (t, v) moves from the first time to the last.
double LineDrift(const std::vector<double>& t, const std::vector<double>& v) {
  const double n = static_cast<double>(t.size());
  double st = 0, sv = 0, stt = 0, stv = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    st += t[i];
    sv += v[i];
    stt += t[i] * t[i];
    stv += t[i] * v[i];
  }
  const double den = n * stt - st * st;
  if (!(den > 0)) return 0;
  return (n * stv - st * sv) / den * (t.back() - t.front());
}

}  // namespace

bool BounceDetectorConfig::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!calibration.IsValid(error)) return false;
  if (!(emit_after_apex_frames >= 0)) return fail("emit after apex must be >= 0 frames");
  if (!(gate_sigmas > 0) || !(min_gate_px > 0)) return fail("gates must be > 0");
  if (!(noise_floor_px > 0) || !(initial_noise_px > 0)) return fail("noise must be > 0 px");
  if (!(release_px > 0)) return fail("release distance must be > 0 px");
  if (!(min_apex_px >= 0)) return fail("minimum apex must be >= 0 px");
  if (!(min_flight_frames >= 0)) return fail("minimum flight must be >= 0 frames");
  if (!(unseen_release_max_s >= 0)) return fail("unseen release time must be >= 0 s");
  if (!(lost_s > 0)) return fail("lost time must be > 0 s");
  if (!(hold_window_s >= 0)) return fail("hold window must be >= 0 s");
  if (!(max_hold_drift > 0)) return fail("hold drift must be > 0");
  if (!(time_scale >= 0) || !std::isfinite(time_scale)) return fail("time scale must be >= 0");
  if (!(capture_slowdown_hint > 0)) return fail("capture slow-down hint must be > 0");
  if (!(clock_tolerance > 0 && clock_tolerance < 1))
    return fail("clock tolerance must be in (0, 1)");
  if (fall_start_samples < 4) return fail("a fall start needs >= 4 samples");
  if (arc_start_samples < 4) return fail("an arc start needs >= 4 samples");
  if (impact_confirm_samples < 1) return fail("impact confirmation needs >= 1 sample");
  if (bounce0_rising_samples < 1) return fail("bounce 0 needs >= 1 rising sample");
  return true;
}

namespace {
BounceDetectorConfig Checked(BounceDetectorConfig c) {
  std::string error;
  if (!c.IsValid(&error)) throw std::invalid_argument("bounce detector: " + error);
  return c;
}
}  // namespace

BounceDetector::BounceDetector(BounceDetectorConfig config)
    : config_(Checked(config)), calibrator_(config.calibration) {
  sigma_ = config_.initial_noise_px;
  if (config_.time_scale > 0) {
    scale_ = config_.time_scale;
    clock_decided_ = true;
    frame_dt_ *= scale_;
  }
}

double BounceDetector::Gate() const {
  return std::max(config_.min_gate_px, config_.gate_sigmas * sigma_);
}

double BounceDetector::MinApexPx() const {
  double flight = 0;
  if (calibrated_) {
    const double t = config_.min_flight_frames * frame_dt_;
    flight = calibration_.flight.globals.gravity_px * t * t / 8;
  }
  return std::max({config_.min_apex_px, 5 * sigma_, flight});
}

double BounceDetector::UnseenReleaseMaxS() const {
  // Before the clock is decided a slowed file's seconds may be `slow-down` times too long.
  const double slow = clock_decided_ ? 1.0 : config_.capture_slowdown_hint;
  return std::max(config_.unseen_release_max_s * slow, 2 * frame_dt_);
}

double BounceDetector::Down(const Sample& s) const {
  return AlongDown(s.x, s.y, calibrated_ ? calibration_.flight.globals.roll_rad : 0.0);
}

double BounceDetector::Floor(const Sample& s) const {
  return AlongFloor(s.x, s.y, calibrated_ ? calibration_.flight.globals.roll_rad : 0.0);
}

int64_t BounceDetector::ToUtime(double t) const { return t0_ + std::llround(t / scale_ * 1e6); }

std::vector<FlightArcData> BounceDetector::ArcData() const {
  std::vector<FlightArcData> out;
  for (const auto& a : arcs_) {
    FlightArcData d;
    d.held_before_apex = a.held;
    for (const auto& s : a.samples) d.samples.push_back({s.t, s.x, s.y});
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<DetectorEvent> BounceDetector::Push(const BallObservation& o) {
  std::vector<DetectorEvent> ev;
  if (!have_t0_) {
    have_t0_ = true;
    t0_ = o.utime;
    last_utime_ = o.utime;
  } else {
    if (o.utime < last_utime_)
      throw std::invalid_argument("bounce detector: observation times went backwards (" +
                                  std::to_string(o.utime) + " < " +
                                  std::to_string(last_utime_) + " us)");
    if (o.utime == last_utime_) return ev;  // a duplicate frame
    frame_dts_.push_back(static_cast<double>(o.utime - last_utime_) * 1e-6 * scale_);
    if (frame_dts_.size() > 64) frame_dts_.erase(frame_dts_.begin());
    frame_dt_ = Median(frame_dts_);
    last_utime_ = o.utime;
  }
  const double t = static_cast<double>(o.utime - t0_) * 1e-6 * scale_;
  const bool usable = o.found && std::isfinite(o.cx) && std::isfinite(o.cy);
  if (!usable) {
    if (phase_ == Phase::kFlight) {
      if (t - last_seen_t_ > config_.lost_s)
        EndSequence("lost", ev);
      else
        TryEmitApex(t, o.utime, false, ev);
    }
    if (phase_ == Phase::kWaiting && !hold_.empty() && t - hold_.back().t > config_.lost_s)
      hold_.clear();
    return ev;
  }
  Sample s;
  s.t = t;
  s.x = o.cx;
  s.y = o.cy;
  s.r = o.radius_px > 0 ? o.radius_px : 0.5 * std::min(o.w, o.h);
  s.utime = o.utime;
  if (s.r > 0) {
    radii_.push_back(s.r);
    if (radii_.size() > 301) radii_.erase(radii_.begin());
  }
  if (phase_ == Phase::kFlight && t - last_seen_t_ > config_.lost_s) EndSequence("lost", ev);
  last_seen_t_ = t;
  switch (phase_) {
    case Phase::kWaiting: OnWaiting(s, ev); break;
    case Phase::kFlight: OnFlight(s, ev); break;
    case Phase::kRest: OnRest(s, ev); break;
  }
  return ev;
}

std::vector<DetectorEvent> BounceDetector::Finish() {
  std::vector<DetectorEvent> ev;
  if (phase_ == Phase::kFlight) EndSequence("end of stream", ev);
  return ev;
}

void BounceDetector::OnWaiting(const Sample& s, std::vector<DetectorEvent>& ev) {
  hold_.push_back(s);
  while (!hold_.empty() && hold_.front().t < s.t - 1.0) hold_.erase(hold_.begin());
  if (!ReleasedFromHold(s, ev) && !FallFromUnseenRelease(s, ev)) ArcFromUnseenStart(s, ev);
}

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
  const auto rows = static_cast<Eigen::Index>(m);
  Eigen::MatrixXd a(rows, 3);
  Eigen::VectorXd b(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const double dt = fall[static_cast<size_t>(i)].t - fall.back().t;
    a(i, 0) = 1;
    a(i, 1) = dt;
    a(i, 2) = dt * dt;
    b(i) = Down(fall[static_cast<size_t>(i)]);
  }
  const Eigen::VectorXd c = a.colPivHouseholderQr().solve(b);
  if (!(c(2) > 0)) return false;
  const double rms = std::sqrt((a * c - b).squaredNorm() / static_cast<double>(m));
  if (rms > Gate()) return false;
  // Far from its vertex already: it came from out of view, not from a hand (see below;
  // twice the margin: five samples place the vertex roughly).
  const double t_vertex = fall.back().t - c(1) / (2 * c(2));
  if (fall.front().t - t_vertex > 2 * UnseenReleaseMaxS()) return false;

  // Released out of sight: a release arc from rest whose vertex is fitted, not seen.
  Arc arc;
  arc.held = false;
  arc.samples = fall;
  StartSequence(std::move(arc), s, ev);
  return true;
}

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
  // A hand moves the ball along gentle curves too. With the ball's size known, free flight
  // bends at g in the size's px/m (on the container's clock): within 4x (a ball given with
  // the wrong preset), not 50x less.
  if (calibrator_.config().ball_diameter_m > 0 && !radii_.empty()) {
    const double size_px_per_m = 2 * Median(radii_) / calibrator_.config().ball_diameter_m;
    const double g_px = calibrator_.config().g_mps2 * size_px_per_m;  // px/s^2, real time
    // Our seconds are real ones, or (clock undecided) maybe `slowdown` times too long.
    auto bends_at = [&](double slowdown) {
      const double expected = g_px / (slowdown * slowdown);
      return 2 * c(2, 0) > expected / 4 && 2 * c(2, 0) < expected * 4;
    };
    if (!bends_at(1) && !(!clock_decided_ && bends_at(config_.capture_slowdown_hint)))
      return false;
  }
  const Eigen::MatrixXd r = a * c - b;
  const double rms_u = std::sqrt(r.col(0).squaredNorm() / static_cast<double>(m));
  const double rms_w = std::sqrt(r.col(1).squaredNorm() / static_cast<double>(m));
  if (rms_u > Gate() || rms_w > Gate()) return false;

  Arc arc;
  arc.samples = run;
  // A fall that starts at its vertex is a release out of sight (bounce 0 is its vertex).
  const double t_vertex = run.back().t - c(1, 0) / (2 * c(2, 0));
  if (t_vertex >= run.front().t - UnseenReleaseMaxS() &&
      t_vertex <= run.front().t + 0.5 * frame_dt_) {
    StartSequence(std::move(arc), s, ev);
    return true;
  }
  arc.entered = true;
  // Its apex is bounce 0 when the ball came from the hand (seen before, not falling into
  // the arc), bounce 1 when it came from an impact or from out of view.
  int first_bounce = 1;
  const size_t before = hold_.size() - m;
  if (before >= 1 && run.front().t - hold_[before - 1].t <= 3 * frame_dt_) {
    const bool falling_in = before >= 2 && Down(hold_[before - 1]) > Down(hold_[before - 2]) + thr;
    first_bounce = falling_in ? 1 : 0;
  }
  StartSequence(std::move(arc), s, ev);
  first_bounce_ = first_bounce;
  return true;
}

bool BounceDetector::EnteredApexSeen() const {
  if (arcs_.empty() || !arcs_[0].entered || !arcs_[0].fit_ok) return false;
  const Arc& a = arcs_[0];
  return a.fit.t_apex >= a.samples.front().t && a.fit.t_apex <= a.samples.back().t;
}

void BounceDetector::StartSequence(Arc release, const Sample& s, std::vector<DetectorEvent>& ev) {
  release.release = !release.entered;
  first_bounce_ = 0;
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

void BounceDetector::OnRest(const Sample& s, std::vector<DetectorEvent>& ev) {
  const double thr = std::max(config_.release_px, Gate());
  if (rest_samples_.empty()) {
    rest_samples_.push_back(s);
    return;
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
    return;
  }
  if (++rest_moves_ >= 3) {
    // Picked up (or kicked): wait for the next hold and release.
    phase_ = Phase::kWaiting;
    hold_.clear();
    rest_samples_.clear();
    rest_moves_ = 0;
    OnWaiting(s, ev);
  }
}

bool BounceDetector::Predict(const Arc& arc, double t, double* u, double* w,
                             double* v_down) const {
  if (calibrated_ && arc.fit_ok) {
    const FlightGlobals& g = calibration_.flight.globals;
    double x, y;
    FlightPosition(g, arc.fit, arc.held, t, &x, &y);
    *u = AlongDown(x, y, g.roll_rad);
    *w = AlongFloor(x, y, g.roll_rad);
    const double tau = t - arc.fit.t_apex;
    *v_down = arc.held && tau < 0 ? 0.0 : FlightVelocityDown(g.gravity_px, g.drag_per_px, tau);
    return true;
  }
  // No model yet (the first fall): a local quadratic through the last moving samples,
  // or, early in a fall from a hold, u = u_hold + A/2 (t - t_release)^2 fitted as a line
  // in sqrt(u - u_hold) (a quadratic through the first few noisy samples extrapolates badly).
  std::vector<const Sample*> moving;
  std::vector<double> hold_u;
  const double thr = 0.5 * std::max(config_.release_px, Gate());
  const double u0 = Down(arc.samples.front());
  for (const auto& s : arc.samples) {
    if (!arc.held || Down(s) - u0 > thr)
      moving.push_back(&s);
    else
      hold_u.push_back(Down(s));
  }
  if (moving.size() < 3) return false;
  if (arc.held && moving.size() < 10 && hold_u.size() >= 3) {
    const double uh = Median(hold_u);
    double st = 0, sq = 0, stt = 0, stq = 0, sw = 0, n = 0;
    for (const Sample* m : moving) {
      const double q = std::sqrt(std::max(0.0, Down(*m) - uh));
      st += m->t;
      sq += q;
      stt += m->t * m->t;
      stq += m->t * q;
      sw += Floor(*m);
      n += 1;
    }
    const double den = n * stt - st * st;
    if (den <= 0) return false;
    const double slope = (n * stq - st * sq) / den;
    const double icpt = (sq - slope * st) / n;
    if (!(slope > 0)) return false;
    const double tr = -icpt / slope;
    const double dt = std::max(0.0, t - tr);
    *u = uh + slope * slope * dt * dt;
    *w = sw / n;
    *v_down = 2 * slope * slope * dt;
    return true;
  }
  if (moving.size() > 12) moving.erase(moving.begin(), moving.end() - 12);
  const auto m = static_cast<Eigen::Index>(moving.size());
  Eigen::MatrixXd a(m, 3);
  Eigen::MatrixXd b(m, 2);
  const double tm = moving.back()->t;
  for (Eigen::Index i = 0; i < m; ++i) {
    const double dt = moving[static_cast<size_t>(i)]->t - tm;
    a(i, 0) = 1;
    a(i, 1) = dt;
    a(i, 2) = dt * dt;
    b(i, 0) = Down(*moving[static_cast<size_t>(i)]);
    b(i, 1) = Floor(*moving[static_cast<size_t>(i)]);
  }
  const Eigen::MatrixXd c = a.colPivHouseholderQr().solve(b);
  const double dt = t - tm;
  *u = c(0, 0) + c(1, 0) * dt + c(2, 0) * dt * dt;
  *w = c(0, 1) + c(1, 1) * dt + c(2, 1) * dt * dt;
  *v_down = c(1, 0) + 2 * c(2, 0) * dt;
  return true;
}

void BounceDetector::RefitArc(Arc& arc) {
  if (!calibrated_) return;
  const FlightGlobals& g = calibration_.flight.globals;
  auto fit = [&](size_t first, FlightArcParams* out, double* u_sigma) {
    FlightArcData d;
    d.held_before_apex = arc.held;
    for (size_t i = first; i < arc.samples.size(); ++i)
      d.samples.push_back({arc.samples[i].t, arc.samples[i].x, arc.samples[i].y});
    std::vector<FlightArcParams> init;
    if (arc.fit_ok) init.push_back(arc.fit);
    const FlightFit f = calibrator_.FitArcs({d}, g, init);
    if (!f.ok) return false;
    *out = f.arcs[0];
    if (u_sigma) *u_sigma = f.u_apex_sigma[0];
    return true;
  };
  // The first sample after an impact may straddle it (the exposure sees the ball fall and
  // rise): while the arc is young, drop it if the others put it off the arc.
  if (!arc.release && arc.samples.size() >= 3 && arc.samples.size() <= 8) {
    FlightArcParams rest;
    if (fit(1, &rest, nullptr)) {
      double x, y;
      FlightPosition(g, rest, false, arc.samples.front().t, &x, &y);
      const double off = std::hypot(x - arc.samples.front().x, y - arc.samples.front().y);
      if (off > Gate()) arc.samples.erase(arc.samples.begin());
    }
  }
  arc.fit_ok = fit(0, &arc.fit, &arc.u_sigma);
}

void BounceDetector::Recalibrate(int64_t utime, std::vector<DetectorEvent>& ev) {
  CalibrationInput in;
  in.utime = utime;
  in.arcs = ArcData();
  in.radius_px = Median(radii_);
  std::vector<FlightArcParams> prev_arcs;
  bool all_fit = calibrated_;
  for (const auto& a : arcs_) {
    all_fit = all_fit && a.fit_ok;
    prev_arcs.push_back(a.fit);
  }
  FlightGlobals prev_globals;
  if (calibrated_) {
    prev_globals = calibration_.flight.globals;
    in.previous_globals = &prev_globals;
    if (all_fit) in.previous_arcs = &prev_arcs;
  }
  CalibrationResult res = calibrator_.Calibrate(in);
  if (!res.flight.ok) return;
  // A later drop of the same camera falls with the same gravity: an arc that says otherwise
  // by far is no free flight (a hand carrying the ball) and must not replace the scale.
  if (calibrated_ && sequence_ > calibration_sequence_ && calibration_.calibration.samples >= 15 &&
      std::abs(std::log(res.calibration.gravity_px / calibration_.calibration.gravity_px)) >
          std::log(1.25))
    return;
  calibration_.calibration.gravity_over_size = res.calibration.gravity_over_size;
  if (!clock_decided_ && arcs_.size() >= 2 && DecideClock()) {
    // The timeline is slowed: every time so far was stream time. Start again in real time.
    in.arcs = ArcData();
    in.previous_globals = nullptr;
    in.previous_arcs = nullptr;
    res = calibrator_.Calibrate(in);
    if (!res.flight.ok) return;
  }
  if (!res.calibration.has_floor && calibrated_ && calibration_.calibration.has_floor) {
    // Same camera, same floor: keep the floor of an earlier drop until this one has one.
    res.calibration.has_floor = true;
    res.calibration.floor_px =
        calibration_.calibration.floor_centre_px() + res.calibration.radius_px;
    res.calibration.floor_sigma_px = calibration_.calibration.floor_sigma_px;
  }
  calibration_ = res;
  calibration_.calibration.time_scale = scale_;
  calibrated_ = true;
  calibration_sequence_ = sequence_;
  for (size_t j = 0; j < arcs_.size() && j < res.flight.arcs.size(); ++j) {
    arcs_[j].fit = res.flight.arcs[j];
    arcs_[j].fit_ok = true;
    arcs_[j].u_sigma = res.flight.u_apex_sigma[j];
  }
  if (res.flight.samples > 10) {
    sigma_ = std::max(config_.noise_floor_px, res.flight.rms_px);
    sigma_measured_ = true;
  }
  DetectorEvent e;
  e.kind = DetectorEvent::Kind::kCalibration;
  e.calibration = calibration_.calibration;
  ev.push_back(e);
}

bool BounceDetector::DecideClock() {
  const double q = calibration_.calibration.gravity_over_size;
  if (!(q > 0)) return false;
  const double tol = std::log1p(config_.clock_tolerance);
  const double hint = config_.capture_slowdown_hint;
  // Only a slow-down the container announces, confirmed by the size, changes the clock.
  if (hint > 1.05 && std::abs(std::log(q * hint * hint)) < tol) {
    clock_decided_ = true;
    RescaleTime(1 / hint);
    return true;
  }
  // Agreement as recorded (or a size that fits no clock: reported, not acted on).
  clock_decided_ = std::abs(std::log(q)) < tol || arcs_.size() >= 3;
  return false;
}

void BounceDetector::RescaleTime(double k) {
  scale_ *= k;
  auto scale = [k](std::vector<Sample>& v) {
    for (auto& q : v) q.t *= k;
  };
  scale(hold_);
  scale(pending_up_);
  scale(pending_off_);
  scale(rest_samples_);
  for (auto& a : arcs_) {
    scale(a.samples);
    a.fit.t_apex *= k;
    a.fit.vw /= k;
    a.fit_ok = false;
  }
  for (auto& d : frame_dts_) d *= k;
  frame_dt_ *= k;
  last_seen_t_ *= k;
  calibrated_ = false;
}

void BounceDetector::OnFlight(const Sample& s, std::vector<DetectorEvent>& ev) {
  Arc& cur = arcs_.back();
  double up, wp, vp;
  if (!Predict(cur, s.t, &up, &wp, &vp)) {
    // The first frames of the first fall: nothing to predict with yet; take what moves on
    // down the same vertical line (a stray detection elsewhere is dropped).
    const Sample& last = cur.samples.back();
    const double g = Gate();
    if (std::abs(Floor(s) - Floor(last)) <= 2 * g && Down(s) >= Down(last) - g &&
        Down(s) - Down(last) <= 20 * g)
      cur.samples.push_back(s);
    return;
  }
  const double u = Down(s), w = Floor(s);
  const double gap_frames = std::max(1.0, (s.t - cur.samples.back().t) / frame_dt_);
  double gate = Gate() + 0.02 * std::abs(vp) * frame_dt_ * gap_frames;
  if (cur.samples.size() < 4 || !calibrated_) gate += 2 * Gate();
  const double ru = u - up, rw = w - wp;
  if (std::abs(ru) <= gate && std::abs(rw) <= 2 * gate) {
    cur.samples.push_back(s);
    pending_up_.clear();
    pending_off_.clear();
    misses_ = 0;
    RefitArc(cur);
    if (!bounce0_emitted_ && arcs_.size() == 2 && arcs_[0].held &&
        static_cast<int>(arcs_[1].samples.size()) >= config_.bounce0_rising_samples) {
      Recalibrate(s.utime, ev);  // the rising branch pins drag against gravity
      EmitPeak(0, s.utime, ev);
    }
    TryEmitApex(s.t, s.utime, true, ev);
    return;
  }
  const bool falling = vp > 0;
  ++misses_;
  if (ru < -gate && falling && std::abs(rw) <= 2 * gate) {
    pending_up_.push_back(s);
    while (static_cast<int>(pending_up_.size()) >= config_.impact_confirm_samples) {
      // A rebound rises: the newest sample must be above the first one off the arc; if it
      // is not, the first one was a stray detection.
      if (pending_up_.size() == 1 || Down(pending_up_.back()) < Down(pending_up_.front())) {
        if (NearTheFloor(cur)) {
          ConfirmImpact(s, ev);
        } else {
          // High above the floor: the arc's young fit turned down too early (few samples
          // at a low frame rate); these samples belong to it.
          for (const auto& q : pending_up_) cur.samples.push_back(q);
          pending_up_.clear();
          pending_off_.clear();
          misses_ = 0;
          RefitArc(cur);
        }
        return;
      }
      pending_up_.erase(pending_up_.begin());
    }
  } else {
    pending_off_.push_back(s);
  }
  if (misses_ >= 6) {
    // Six frames in a row off the arc: it has ended (at rest, caught, rolling away).
    const bool near_floor = calibrated_ && calibration_.calibration.has_floor &&
                            std::abs(u - calibration_.calibration.floor_centre_px()) <=
                                3 * Gate();
    std::vector<Sample> recent = pending_off_;
    recent.insert(recent.end(), pending_up_.begin(), pending_up_.end());
    std::sort(recent.begin(), recent.end(),
              [](const Sample& x, const Sample& y) { return x.t < y.t; });
    EndSequence(near_floor ? "rest" : "broken", ev);
    if (!near_floor)
      for (const auto& o : recent) OnWaiting(o, ev);
  }
}

bool BounceDetector::NearTheFloor(const Arc& cur) const {
  if (!calibrated_ || !calibration_.calibration.has_floor || !cur.fit_ok) return true;
  const double floor = calibration_.calibration.floor_centre_px();
  const double apex = floor - cur.fit.u_apex;
  if (!(apex > MinApexPx())) return true;
  // Around an impact the samples either side lie within one frame's travel of the floor,
  // so the lower of the two is in the lower part of the arc; near the apex both are high.
  const double low = floor - std::max(Down(cur.samples.back()), Down(pending_up_.front()));
  return low < 0.6 * apex;
}

void BounceDetector::ConfirmImpact(const Sample& s, std::vector<DetectorEvent>& ev) {
  // The last sample of the falling arc may straddle the impact too: drop it if the samples
  // before it put it off the arc (it would bend the fall, and the scale with it).
  {
    Arc& prev = arcs_.back();
    if (prev.samples.size() >= 6) {
      Arc probe = prev;
      const Sample last = probe.samples.back();
      probe.samples.pop_back();
      if (calibrated_) RefitArc(probe);
      double up, wp, vp;
      if (Predict(probe, last.t, &up, &wp, &vp) &&
          std::abs(Down(last) - up) > Gate() + 0.02 * std::abs(vp) * frame_dt_)
        prev.samples.pop_back();
    }
  }
  Arc next;
  next.samples = pending_up_;
  pending_up_.clear();
  pending_off_.clear();
  misses_ = 0;
  arcs_.push_back(next);
  Recalibrate(s.utime, ev);
  const size_t idx = arcs_.size() - 1;
  if (calibrated_ && idx - 1 < calibration_.impacts.size() &&
      calibration_.impacts[idx - 1].ok && calibration_.calibration.valid()) {
    const FlightImpact& imp = calibration_.impacts[idx - 1];
    BounceImpact bi;
    bi.sequence = sequence_;
    bi.index = static_cast<int>(idx) + first_bounce_;
    bi.utime = ToUtime(imp.t);
    bi.speed_in_mps = imp.speed_in / calibration_.calibration.px_per_m;
    bi.speed_out_mps = imp.speed_out / calibration_.calibration.px_per_m;
    bi.restitution = imp.speed_in > 0 ? imp.speed_out / imp.speed_in : 0;
    impacts_.push_back(bi);
    DetectorEvent e;
    e.kind = DetectorEvent::Kind::kImpact;
    e.impact = bi;
    ev.push_back(e);
  }
  // An arc whose apex went unreported (seen too briefly, or hidden, or the arc that began
  // the sequence in flight): report it late.
  if ((idx >= 2 || arcs_[0].entered) && !arcs_[idx - 1].apex_emitted && calibrated_ &&
      arcs_[idx - 1].fit_ok) {
    const double h = calibration_.calibration.floor_centre_px() - arcs_[idx - 1].fit.u_apex;
    if (h >= MinApexPx()) EmitPeak(idx - 1, s.utime, ev);
  }
  if (!bounce0_emitted_ && idx == 1 && arcs_[0].held &&
      static_cast<int>(arcs_[1].samples.size()) >= config_.bounce0_rising_samples)
    EmitPeak(0, s.utime, ev);
}

void BounceDetector::TryEmitApex(double t, int64_t utime, bool have_sample,
                                 std::vector<DetectorEvent>& ev) {
  if (arcs_.size() < 2 || !calibrated_) return;
  const size_t idx = arcs_.size() - 1;
  Arc& arc = arcs_[idx];
  if (arc.apex_emitted || !arc.fit_ok) return;
  if (arc.samples.size() < (have_sample ? 3u : 5u)) return;
  const double margin = config_.emit_after_apex_frames * frame_dt_;
  if (t < arc.fit.t_apex + margin) return;
  Recalibrate(utime, ev);
  if (!arcs_[idx].fit_ok || t < arcs_[idx].fit.t_apex + margin) return;
  const double h = calibration_.calibration.floor_centre_px() - arcs_[idx].fit.u_apex;
  if (h < MinApexPx()) {
    EndSequence("rest", ev);
    return;
  }
  EmitPeak(idx, utime, ev);
}

void BounceDetector::EmitPeak(size_t j, int64_t utime, std::vector<DetectorEvent>& ev) {
  const Calibration& cal = calibration_.calibration;
  if (j >= arcs_.size() || !cal.valid() || !cal.has_floor || !arcs_[j].fit_ok) return;
  // Peaks go out in bounce order: a release height still pending goes first.
  if (j > 0 && !bounce0_emitted_) EmitPeak(0, utime, ev);
  Arc& arc = arcs_[j];
  if (j == 0 && arc.entered && !EnteredApexSeen()) {
    bounce0_emitted_ = true;  // entered falling: its apex was never in view
    return;
  }
  BouncePeak p;
  p.utime = utime;
  p.sequence = sequence_;
  p.bounce = static_cast<int>(j) + first_bounce_;
  p.apex_utime = ToUtime(arc.fit.t_apex);
  p.height_px = cal.floor_centre_px() - arc.fit.u_apex;
  // The release arc's apex is its fitted vertex (seen held, or extrapolated from the fall).
  if (config_.use_arc_apex && !arc.release) {
    // Heights above the floor with the drag's departure from a parabola removed.
    const FlightGlobals& g = calibration_.flight.globals;
    std::vector<double> ts, hs;
    for (const auto& q : arc.samples) {
      const double tau = q.t - arc.fit.t_apex;
      if (std::abs(tau) > config_.arc_apex_window_s) continue;
      const double drag = FlightDrop(g.gravity_px, g.drag_per_px, tau) - 0.5 * g.gravity_px * tau * tau;
      ts.push_back(q.t);
      hs.push_back(cal.floor_centre_px() - Down(q) + drag);
    }
    const ArcApex a = FitArcApex(ts, hs);
    if (a.ok && ts.size() >= 5 && std::abs(a.t - arc.fit.t_apex) < frame_dt_) {
      p.height_px = a.height;
      p.apex_utime = ToUtime(a.t);
    }
  }
  // An apex at or below the floor is no bounce (the arc was not free flight).
  if (p.height_px < MinApexPx()) {
    if (j == 0) bounce0_emitted_ = true;
    arc.apex_emitted = true;
    return;
  }
  p.height_m = p.height_px / cal.px_per_m;
  const double rel = cal.px_per_m_sigma / cal.px_per_m;
  p.height_sigma_m = std::hypot(std::hypot(arc.u_sigma, cal.floor_sigma_px) / cal.px_per_m,
                                p.height_m * rel);
  for (const auto& imp : impacts_)
    if (imp.index == p.bounce) p.impact_before_utime = imp.utime;
  p.emitted_utime = utime;
  arc.apex_emitted = true;
  if (j == 0) bounce0_emitted_ = true;
  peaks_.push_back(p);
  DetectorEvent e;
  e.kind = DetectorEvent::Kind::kPeak;
  e.peak = p;
  ev.push_back(e);
}

void BounceDetector::EndSequence(const std::string& reason, std::vector<DetectorEvent>& ev) {
  if (sequence_ >= 0 && !arcs_.empty()) {
    // A last look with every arc: final heights, flight-time heights, restitution.
    if (arcs_.size() >= 2) Recalibrate(last_utime_, ev);
    // A release not seen held waits for the first rebound's apex; it has none (too low).
    if (!bounce0_emitted_ && arcs_.size() >= 2 && !arcs_[0].held) EmitPeak(0, last_utime_, ev);
    SequenceSummary sum;
    sum.sequence = sequence_;
    sum.first_bounce = first_bounce_;
    sum.end_reason = reason;
    sum.peaks = peaks_;
    sum.calibration = calibration_.calibration;
    // Impacts from the final refit (the streamed ones saw two or three rising samples).
    for (size_t j = 0; j < calibration_.impacts.size() && j + 1 < arcs_.size(); ++j) {
      const FlightImpact& imp = calibration_.impacts[j];
      if (!imp.ok || !calibration_.calibration.valid()) continue;
      BounceImpact bi;
      bi.sequence = sequence_;
      bi.index = static_cast<int>(j + 1) + first_bounce_;
      bi.utime = ToUtime(imp.t);
      bi.speed_in_mps = imp.speed_in / calibration_.calibration.px_per_m;
      bi.speed_out_mps = imp.speed_out / calibration_.calibration.px_per_m;
      bi.restitution = imp.speed_in > 0 ? imp.speed_out / imp.speed_in : 0;
      sum.impacts.push_back(bi);
    }
    const Calibration& cal = calibration_.calibration;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const bool metres = calibrated_ && cal.valid() && cal.has_floor;
    std::vector<double> impact_t;
    for (size_t j = 0; j + 1 < arcs_.size() && j < calibration_.impacts.size(); ++j)
      impact_t.push_back(calibration_.impacts[j].ok ? calibration_.impacts[j].t : nan);
    for (size_t j = 0; j < arcs_.size(); ++j) {
      sum.final_height_m.push_back(
          metres && arcs_[j].fit_ok ? (cal.floor_centre_px() - arcs_[j].fit.u_apex) / cal.px_per_m
                                    : nan);
      double fh = nan;
      if (j >= 1 && j < impact_t.size()) {
        const double dt = impact_t[j] - impact_t[j - 1];
        fh = calibrator_.config().g_mps2 * dt * dt / 8;
      }
      sum.flight_height_m.push_back(fh);
    }
    // Emitted peaks learn their closing impact and flight height here.
    for (auto& p : sum.peaks) {
      const auto b = static_cast<size_t>(p.bounce - first_bounce_);
      if (b < sum.flight_height_m.size()) p.flight_height_m = sum.flight_height_m[b];
      if (b < impact_t.size() && std::isfinite(impact_t[b])) p.impact_after_utime = ToUtime(impact_t[b]);
    }
    if (sum.impacts.size() >= 2) {
      double sx = 0, sy = 0, sxx = 0, sxy = 0;
      const double n = static_cast<double>(sum.impacts.size());
      for (const auto& i : sum.impacts) {
        sx += i.speed_in_mps;
        sy += i.restitution;
        sxx += i.speed_in_mps * i.speed_in_mps;
        sxy += i.speed_in_mps * i.restitution;
      }
      const double den = n * sxx - sx * sx;
      if (std::abs(den) > 1e-12) {
        sum.restitution_slope_per_mps = (n * sxy - sx * sy) / den;
        sum.restitution_intercept = (sy - sum.restitution_slope_per_mps * sx) / n;
      }
    }
    summaries_.push_back(sum);
    DetectorEvent e;
    e.kind = DetectorEvent::Kind::kSequenceEnd;
    e.reason = reason;
    ev.push_back(e);
  }
  arcs_.clear();
  pending_up_.clear();
  pending_off_.clear();
  misses_ = 0;
  peaks_.clear();
  impacts_.clear();
  hold_.clear();
  rest_samples_.clear();
  rest_moves_ = 0;
  phase_ = reason == "rest" ? Phase::kRest : Phase::kWaiting;
}

}  // namespace bouncefit
