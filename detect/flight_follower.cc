// Following a drop in flight: predicting and refitting each arc, judging each sample
// against it, and keeping a young arc from losing its own samples.
#include "detect/flight_follower.h"
#include "detect/detector_stats.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit {

using detector_stats::Median;
using detector_stats::ParabolaAt;

constexpr int kMissesEndArc = 6;  // samples in a row off an arc that end it

FlightFollower::FlightFollower(const FlightFollowerConfig& config, DetectorScene& scene,
                               DropHost& host)
    : config_(config), scene_(scene), host_(host) {}

void FlightFollower::Start(DetectorArc first) {
  arcs_.clear();
  arcs_.push_back(std::move(first));
  pending_up_.clear();
  pending_off_.clear();
}

void FlightFollower::Saw(const DetectorSample& s) {
  if (flight_seen_.size() < kFlightSeenKept) flight_seen_.push_back(s);
}

void FlightFollower::Reset() {
  arcs_.clear();
  flight_seen_.clear();
  pending_up_.clear();
  pending_off_.clear();
  last_far_.reset();
  misses_ = 0;
}

void FlightFollower::RescaleTime(double k) {
  auto scale = [k](std::vector<DetectorSample>& v) {
    for (auto& q : v) q.t *= k;
  };
  scale(pending_up_);
  scale(pending_off_);
  scale(flight_seen_);
  for (auto& a : arcs_) {
    scale(a.samples);
    a.fit.t_apex *= k;
    a.fit.vw /= k;
    a.fit_ok = false;
  }
}

std::vector<FlightArcData> FlightFollower::ArcData() const {
  std::vector<FlightArcData> out;
  for (const auto& a : arcs_) {
    FlightArcData d;
    d.held_before_apex = a.held;
    for (const auto& s : a.samples) d.samples.push_back({s.t, s.x, s.y});
    out.push_back(std::move(d));
  }
  return out;
}

void FlightFollower::TakeFits(const FlightFit& flight) {
  for (size_t j = 0; j < arcs_.size() && j < flight.arcs.size(); ++j) {
    arcs_[j].fit = flight.arcs[j];
    arcs_[j].fit_ok = true;
    arcs_[j].u_sigma = flight.u_apex_sigma[j];
  }
}

bool FlightFollower::Predict(const DetectorArc& arc, double t, double* u, double* w,
                             double* v_down) const {
  if (scene_.calibrated() && arc.fit_ok) {
    const FlightGlobals& g = scene_.calibration().flight.globals;
    double x, y;
    FlightPosition(g, arc.fit, arc.held, t, &x, &y);
    *u = AlongDown(x, y, g.roll_rad);
    *w = AlongFloor(x, y, g.roll_rad);
    const double tau = t - arc.fit.t_apex;
    const bool in_hand = arc.held && tau < arc.fit.lead_s;
    *v_down = in_hand ? 0.0 : FlightVelocityDown(g.gravity_px, g.drag_per_px, tau);
    return true;
  }
  // No model yet (the first fall): a local quadratic through the last moving samples,
  // or, early in a fall from a hold, u = u_hold + A/2 (t - t_release)^2 fitted as a line
  // in sqrt(u - u_hold) (a quadratic through the first few noisy samples extrapolates badly).
  std::vector<const DetectorSample*> moving;
  std::vector<double> hold_u;
  for (size_t i = 0; i < arc.samples.size(); ++i) {
    if (i < arc.hold_samples)
      hold_u.push_back(Down(arc.samples[i]));
    else
      moving.push_back(&arc.samples[i]);
  }
  // Two samples below a seen hold pin that curve (u_hold is known): at 24 fps the third
  // sample of a fall is already tens of pixels further than the second went.
  if (arc.held && moving.size() >= 2 && moving.size() < 10 && hold_u.size() >= 3) {
    const double uh = Median(hold_u);
    // Weighted by the drop: a pixel of noise moves sqrt(u - u_hold) by 1 / (2 sqrt(u - u_hold)),
    // so the first samples below the hand, a few pixels down, say least about the fall.
    double st = 0, sq = 0, stt = 0, stq = 0, n = 0, w_sum = 0;
    for (const DetectorSample* m : moving) {
      const double d = std::max(0.0, Down(*m) - uh);
      const double q = std::sqrt(d);
      const double wt = std::max(d, 1.0);
      st += wt * m->t;
      sq += wt * q;
      stt += wt * m->t * m->t;
      stq += wt * m->t * q;
      n += wt;
      w_sum += Floor(*m);
    }
    const double den = n * stt - st * st;
    if (den <= 0) return false;
    const double slope = (n * stq - st * sq) / den;
    const double icpt = (sq - slope * st) / n;
    if (!(slope > 0)) return false;
    const double tr = -icpt / slope;
    const double dt = std::max(0.0, t - tr);
    *u = uh + slope * slope * dt * dt;
    *w = w_sum / static_cast<double>(moving.size());
    *v_down = 2 * slope * slope * dt;
    return true;
  }
  if (moving.size() < 3) return false;
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
  *u = ParabolaAt(c.col(0), dt);
  *w = ParabolaAt(c.col(1), dt);
  *v_down = c(1, 0) + 2 * c(2, 0) * dt;
  return true;
}

void FlightFollower::RefitArc(DetectorArc& arc) {
  if (!scene_.calibrated()) return;
  const FlightGlobals& g = scene_.calibration().flight.globals;
  auto fit = [&](size_t first, FlightArcParams* out, double* u_sigma) {
    FlightArcData d;
    d.held_before_apex = arc.held;
    for (size_t i = first; i < arc.samples.size(); ++i)
      d.samples.push_back({arc.samples[i].t, arc.samples[i].x, arc.samples[i].y});
    std::vector<FlightArcParams> init;
    if (arc.fit_ok) init.push_back(arc.fit);
    const FlightFit f = scene_.calibrator().FitArcs({d}, g, init);
    if (!f.ok) return false;
    *out = f.arcs[0];
    if (u_sigma) *u_sigma = f.u_apex_sigma[0];
    return true;
  };
  // The first sample after an impact may straddle it (the exposure sees the ball fall and
  // rise): while the arc is young, drop it if the others put it off the arc. Only a sample
  // within a frame or so of the impact can straddle it. A later one may be a smeared streak or
  // a box merged with a shadow, a good part of the ball's radius off; a few pixels off may be
  // the gravity of the short first arc the scale rests on (a throw moving away from the
  // camera measured it 45% low), and dropping sample after sample for that kept a rebound's
  // arc at three to five samples until the drop broke.
  const FlightImpact* began = ImpactBeforeCurrentArc();
  if (!arc.release && arc.samples.size() >= 3 && arc.samples.size() <= 8) {
    FlightArcParams rest;
    if (fit(1, &rest, nullptr)) {
      const DetectorSample& front = arc.samples.front();
      double x, y;
      FlightPosition(g, rest, false, front.t, &x, &y);
      // Judged by two samples, along the floor the rest's course is a guess (two samples do
      // not free the horizontal speed): only the height then (a ball that straddles its impact
      // is off in height; one whose box merged with the floor's shadow, by a guess across).
      const double off = arc.samples.size() == 3
                             ? std::abs(AlongDown(x, y, g.roll_rad) - Down(front))
                             : std::hypot(x - front.x, y - front.y);
      const bool may_straddle =
          !began || front.t <= began->t + config_.straddle_frames * scene_.frame_dt();
      const double limit =
          may_straddle ? scene_.Gate()
          : arc.late_drops < config_.max_late_drops
              ? std::max(scene_.Gate(), config_.off_arc_radius_share * scene_.RadiusPx())
              : std::numeric_limits<double>::infinity();
      if (off > limit) {
        arc.samples.erase(arc.samples.begin());
        if (!may_straddle) ++arc.late_drops;
      }
    }
  }
  arc.fit_ok = fit(0, &arc.fit, &arc.u_sigma);
}

double FlightFollower::ScaleGatePx(const DetectorArc& arc, double t) const {
  // Only the first rebound is followed with the scale of a fall alone.
  if (!scene_.calibrated() || arc.samples.size() < 2 || arcs_.size() != 2 || arc.apex_emitted) return 0;
  const Calibration& cal = scene_.calibration().calibration;
  if (cal.px_per_m <= 0) return 0;
  // An arc fitted through its samples with a gravity off by dg departs from them by
  // dg/2 ((t - tc)^2 - var(t_i)) at t (tc: their mean time, the fit absorbs the rest).
  double tc = 0, tt = 0;
  for (const auto& q : arc.samples) tc += q.t, tt += q.t * q.t;
  const double n = static_cast<double>(arc.samples.size());
  tc /= n;
  const double var = std::max(0.0, tt / n - tc * tc);
  const double reach = std::max(0.0, (t - tc) * (t - tc) - var);
  const double rel =
      std::max(cal.px_per_m_sigma / cal.px_per_m, config_.first_scale_min_rel_sigma);
  const double dg =
      config_.scale_gate_sigmas * rel * std::abs(scene_.calibration().flight.globals.gravity_px);
  return 0.5 * dg * reach;
}

double FlightFollower::SidewaysSpeed(const DetectorArc& arc) const {
  if (scene_.calibrated() && arc.fit_ok) return arc.fit.vw;
  const auto& q = arc.samples;
  if (q.size() < 2) return 0;
  const DetectorSample& a = q[q.size() >= 4 ? q.size() - 4 : 0];
  const DetectorSample& b = q.back();
  return b.t > a.t ? (Floor(b) - Floor(a)) / (b.t - a.t) : 0;
}

void FlightFollower::OnFlight(const DetectorSample& s, std::vector<DetectorEvent>& ev) {
  DetectorArc& cur = arcs_.back();
  double up, wp, vp;
  if (!Predict(cur, s.t, &up, &wp, &vp)) {
    // The first frames of an arc with no scale yet to follow it by: take what moves on the
    // same vertical line (a stray detection elsewhere is dropped), down in the first fall, up
    // in the rebounds after a fall seen from its hold too short to measure gravity by (three
    // samples below the hold at least: a "fall" of one is no flight of the ball's).
    const DetectorSample& last = cur.samples.back();
    const double g = scene_.Gate();
    const DetectorArc& first = arcs_.front();
    const bool rising = !cur.release && first.held &&
                        first.samples.size() >= first.hold_samples + 3;
    const double on = rising ? Down(last) - Down(s) : Down(s) - Down(last);
    // A rebound slows as it rises: a step no longer than the one before it.
    double most = 20 * g;
    if (rising && cur.samples.size() >= 2)
      most = std::max(most, Down(cur.samples[cur.samples.size() - 2]) - Down(last) + 2 * g);
    if (std::abs(Floor(s) - Floor(last)) <= 2 * g && on >= -g && on <= most) cur.samples.push_back(s);
    return;
  }
  const double u = Down(s), w = Floor(s);
  const double gap_frames = std::max(1.0, (s.t - cur.samples.back().t) / scene_.frame_dt());
  double gate = scene_.FollowGate(vp, gap_frames);
  if (cur.samples.size() < 4 || !scene_.calibrated()) gate += 2 * scene_.Gate();
  // Until the drop's noise is measured, an arc whose own samples scatter more than assumed
  // (a smeared ball at 20-30 fps is located to pixels, not tenths) is followed with its scatter.
  if (!scene_.sigma_measured()) gate = std::max(gate, scene_.config().gate_sigmas * ArcScatter(cur));
  gate += ScaleGatePx(cur, s.t);
  const double ru = u - up, rw = w - wp;
  // Farther from the arc than any rebound could have carried the ball since its last sample
  // (twice its speed over the gap, four radii and ten gates), and where the last such
  // detection was: something standing still elsewhere while the tracker has lost the ball (a
  // lookalike where the ball was held). Not a sample, not a sign that the arc ended: the drop
  // waits as if the ball were unseen. A far detection that moves may be the ball on a path the
  // arc did not foresee (a release the hold hid): it is off the arc as before.
  // Across, the reach is the arc's own sideways speed and the noise: past the floor the fall's
  // extrapolated speed, and the gate with it, grow every frame and would soon reach anywhere (a
  // lookalike at the picture's edge while a thrown ball bounced unseen, six frames at 30 fps,
  // ended its drop).
  const double reach = 2 * std::abs(vp) * scene_.frame_dt() * gap_frames + 4 * s.r + 10 * gate;
  const double across_reach =
      2 * std::abs(SidewaysSpeed(cur)) * scene_.frame_dt() * gap_frames + 4 * s.r + 10 * scene_.Gate();
  const bool far = std::hypot(ru, rw) > reach || std::abs(rw) > across_reach;
  const bool still_far = far && last_far_ && std::hypot(s.x - last_far_->x, s.y - last_far_->y) <= s.r + gate;
  last_far_.reset();
  if (far) last_far_ = s;
  if (still_far) {
    double last_seen_t = cur.samples.back().t;
    for (const auto* pending : {&pending_off_, &pending_up_})
      if (!pending->empty()) last_seen_t = std::max(last_seen_t, pending->back().t);
    scene_.set_last_seen_t(last_seen_t);
    host_.OnNoSample(s.t, s.utime, ev);
    return;
  }
  // Before the first calibration a fall from the hand is followed with a guess from its first
  // few samples, a few pixels below the hand, where a pixel of noise is much of the drop (a
  // smeared 24 fps fall is located to pixels): a sample beyond that guess, below or above it,
  // further down the same line is the fall going faster or slower than guessed, not the end of
  // it (above, it is no rebound: the ball is lower than at its last sample).
  // Only while the fall is young (followed as a fall from the hand, under 10 samples): a "fall"
  // the hand drew slowly for seconds before the ball dropped is no guess to outrun.
  const bool young_fall_off_guess = !scene_.calibrated() && cur.release && cur.held &&
                                    cur.samples.size() < cur.hold_samples + 10 &&
                                    std::abs(ru) > gate && std::abs(ru) < 0.5 * reach &&
                                    std::abs(rw) <= 2 * gate && Down(s) > Down(cur.samples.back());
  if ((std::abs(ru) <= gate || young_fall_off_guess) && std::abs(rw) <= 2 * gate) {
    cur.samples.push_back(s);
    pending_up_.clear();
    pending_off_.clear();
    misses_ = 0;
    RefitArc(cur);
    host_.OnSampleKept(s, ev);
    return;
  }
  // Off the arc past its fitted apex, the apex not out yet: the scale the arc is followed with
  // may be what is off (a first fall's gravity from a few smeared frames, 12% high on a clip
  // of a ball dropped on a table). Emitting the apex refits the scale with this arc's samples;
  // then the sample is judged again.
  if (!rejudging_ && scene_.calibrated() && cur.fit_ok && !cur.apex_emitted && !cur.apex_held && arcs_.size() >= 2 &&
      host_.ApexDue(cur, s.t)) {
    const double scale_before = scene_.scale();
    const int sequence_before = host_.Sequence();
    host_.OnNoSample(s.t, s.utime, ev);
    if (!host_.InFlight() || host_.Sequence() != sequence_before) return;
    DetectorSample again = s;
    again.t *= scene_.scale() / scale_before;  // the clock may have been decided by that refit
    rejudging_ = true;
    OnFlight(again, ev);
    rejudging_ = false;
    return;
  }
  const bool falling = vp > 0;
  ++misses_;
  // Along the floor a rebound keeps its course to within the gate and what its impact did to
  // its speed there (friction, spin, a wall: up to all of it) since the last sample: the ball
  // may have been unseen through the impact (a small ball smeared into a pale streak at
  // 25 fps, lost for 9 frames, rebounding at a third of its speed along the floor).
  double vw = 0;
  if (cur.fit_ok) {
    vw = cur.fit.vw;
  } else if (cur.samples.size() >= 2) {
    const DetectorSample& a = cur.samples[cur.samples.size() - 2];
    const DetectorSample& b = cur.samples.back();
    if (b.t > a.t) vw = (Floor(b) - Floor(a)) / (b.t - a.t);
  }
  const double along_gate = 2 * gate + std::abs(vw) * (s.t - cur.samples.back().t);
  if (ru < -gate && falling && std::abs(rw) <= along_gate) {
    pending_up_.push_back(s);
    if (AdoptOffArcSamples(cur)) return;
    while (static_cast<int>(pending_up_.size()) >= config_.impact_confirm_samples) {
      // A rebound rises: the newest sample must be above the first one off the arc; if it
      // is not, the first one was a stray detection.
      if (pending_up_.size() == 1 || Down(pending_up_.back()) < Down(pending_up_.front())) {
        if (NearTheFloor(cur)) {
          if (ImpactNotSeen()) {
            // No impact: the front sample starts no rebound (the arc ends by its misses).
            pending_up_.erase(pending_up_.begin());
            continue;
          }
          if (StraddlesItsImpact(cur)) ForgetStraddlingArc();
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
    if (AdoptOffArcSamples(cur)) return;
  }
  if (misses_ >= kMissesEndArc) {
    // Six frames in a row off the arc: it has ended (at rest, caught, rolling away).
    const bool near_floor = scene_.calibrated() && scene_.calibration().calibration.has_floor &&
                            std::abs(u - scene_.calibration().calibration.floor_centre_px()) <=
                                3 * scene_.Gate();
    std::vector<DetectorSample> recent = pending_off_;
    recent.insert(recent.end(), pending_up_.begin(), pending_up_.end());
    std::sort(recent.begin(), recent.end(),
              [](const DetectorSample& x, const DetectorSample& y) { return x.t < y.t; });
    Eigen::Vector3d fall;
    if (!near_floor && YoungFallContinues(cur, recent, &fall)) {
      // The release arc's young model lost its own fall (a push, a smeared 24 fps fall):
      // the samples it turned away are that fall, not the end of the drop. An arc not seen
      // held keeps only its samples on that fall: the still ones it began with were the hand.
      if (!cur.held) {
        const double t_last = recent.back().t, g = scene_.StartGate();
        std::erase_if(cur.samples, [&](const DetectorSample& q) {
          return std::abs(Down(q) - ParabolaAt(fall, q.t - t_last)) > g;
        });
      }
      cur.samples.insert(cur.samples.end(), recent.begin(), recent.end());
      pending_up_.clear();
      pending_off_.clear();
      misses_ = 0;
      RefitArc(cur);
      return;
    }
    if (!near_floor && ArcContinues(cur, recent)) {
      // The arc went on in free flight; the drop's gravity, fitted mostly to another arc (a
      // first fall on a slow-motion ramp, a push), is what turned it away: refit it with them.
      cur.samples.insert(cur.samples.end(), recent.begin(), recent.end());
      pending_up_.clear();
      pending_off_.clear();
      misses_ = 0;
      host_.Recalibrate(s.utime, ev);
      RefitArc(cur);
      return;
    }
    host_.EndSequence(near_floor ? "rest" : "broken", ev);
    if (!near_floor)
      for (const auto& o : recent) host_.OnWaiting(o, ev);
  }
}

bool FlightFollower::AdoptOffArcSamples(DetectorArc& cur) {
  // A rebound's first samples at a low frame rate: the one straddling the impact is smeared,
  // and an arc of two or three samples extrapolates its error for every frame after (at
  // 24 fps the next sample is then tens of pixels off). When the samples it turned away, high
  // or low, agree with one arc together with its samples that fit too, they are that
  // rebound, not a new impact or the end of the drop.
  std::vector<DetectorSample> missed = pending_off_;
  missed.insert(missed.end(), pending_up_.begin(), pending_up_.end());
  if (!scene_.calibrated() || cur.release || cur.samples.size() > 3 || missed.size() < 2) return false;
  std::sort(missed.begin(), missed.end(), [](const DetectorSample& x, const DetectorSample& y) { return x.t < y.t; });
  const FlightGlobals& g = scene_.calibration().flight.globals;
  auto offset = [&](const DetectorArc& a, const DetectorSample& q) {
    double x, y;
    FlightPosition(g, a.fit, a.held, q.t, &x, &y);
    return std::hypot(x - q.x, y - q.y);
  };
  DetectorArc trial = cur;
  for (const auto& q : missed) trial.samples.push_back(q);
  for (size_t kept = cur.samples.size();; --kept) {
    trial.fit_ok = false;
    RefitArc(trial);  // drops a first sample the others put off the arc
    if (!trial.fit_ok || trial.samples.size() < 3) return false;
    double worst = 0;
    for (const auto& q : trial.samples) worst = std::max(worst, offset(trial, q));
    if (worst <= 3 * scene_.StartGate()) break;  // a young arc's gate (the noise maybe not measured)
    // The arc's own first samples may be the ones off (straddling the impact): drop them.
    if (kept == 0 || offset(trial, trial.samples.front()) < worst) return false;
    trial.samples.erase(trial.samples.begin());
  }
  // An arc that left the floor well after the impact that began this one is another arc
  // (after an impact this arc missed): that is for the impact to confirm, not for this arc to
  // swallow. One that left it then is this rebound, even without any of the arc's own samples
  // (its first two, smeared rising from the floor at 25 fps, 25-35 px off it).
  const FlightImpact* began = ImpactBeforeCurrentArc();
  if (began && scene_.calibration().calibration.has_floor) {
    const double rise = scene_.calibration().calibration.floor_centre_px() - trial.fit.u_apex;
    const double left_floor = trial.fit.t_apex - std::sqrt(2 * std::max(0.0, rise) / g.gravity_px);
    if (left_floor > began->t + 1.5 * scene_.frame_dt()) return false;
  } else if (trial.samples.front().t > cur.samples.back().t) {
    return false;
  }
  cur = std::move(trial);
  pending_off_.clear();
  pending_up_.clear();
  misses_ = 0;
  return true;
}

bool FlightFollower::YoungFallContinues(const DetectorArc& cur,
                                        const std::vector<DetectorSample>& missed,
                                        Eigen::Vector3d* fall_parabola) const {
  // Only a release arc not yet calibrated, before any impact, turning away samples that are
  // one fall: each lower than the one before it, from the arc's last sample on, falling
  // faster and faster along one parabola (within the start gate).
  if (!cur.release || scene_.calibrated() || arcs_.size() != 1 || cur.samples.empty() || missed.size() < 3)
    return false;
  std::vector<DetectorSample> fall{cur.samples.back()};
  for (const DetectorSample& q : missed) {
    if (q.t <= fall.back().t || Down(q) <= Down(fall.back())) return false;
    fall.push_back(q);
  }
  double rms = 0;
  *fall_parabola = scene_.DownParabola(fall, &rms);
  const double bend = (*fall_parabola)(2);
  // Free flight for the ball's size on some clock the file may have, not a hand's curve.
  return bend > 0 && rms <= scene_.StartGate() && scene_.SlowdownOfBend(2 * bend) > 0;
}

bool FlightFollower::ArcContinues(const DetectorArc& cur, const std::vector<DetectorSample>& missed) const {
  // A calibrated arc long enough to measure its own bend, and every sample it turned away
  // after its last one, on one free parabola with it: each within the noise gate, the whole
  // within half of it, bent by a gravity within a quarter of the drop's (a hand's carry or a
  // lookalike is neither).
  constexpr size_t kMinArcSamples = 8;
  if (!scene_.calibrated() || !cur.fit_ok || cur.release || cur.samples.size() < kMinArcSamples ||
      missed.empty() || missed.front().t <= cur.samples.back().t)
    return false;
  std::vector<DetectorSample> run = cur.samples;
  run.insert(run.end(), missed.begin(), missed.end());
  double rms = 0;
  const Eigen::Vector3d arc = scene_.DownParabola(run, &rms);
  const double g_px = scene_.calibration().flight.globals.gravity_px;
  const double bend = 2 * arc(2);
  if (g_px <= 0 || rms > 0.5 * scene_.Gate() || std::abs(bend / g_px - 1) > 0.25) return false;
  const double t_last = run.back().t;
  for (const DetectorSample& q : missed)
    if (std::abs(Down(q) - ParabolaAt(arc, q.t - t_last)) > scene_.Gate()) return false;
  return true;
}

double FlightFollower::ArcScatter(const DetectorArc& arc) const {
  constexpr int kArcParams = 4;  // apex time, height and horizontal place, horizontal speed
  const int coords = 2 * static_cast<int>(arc.samples.size());
  if (!scene_.calibrated() || !arc.fit_ok || coords - kArcParams < 4) return 0;
  const FlightGlobals& g = scene_.calibration().flight.globals;
  double ss = 0;
  for (const auto& q : arc.samples) {
    double x, y;
    FlightPosition(g, arc.fit, arc.held, q.t, &x, &y);
    ss += (x - q.x) * (x - q.x) + (y - q.y) * (y - q.y);
  }
  return std::sqrt(ss / (coords - kArcParams));
}

}  // namespace bouncefit
