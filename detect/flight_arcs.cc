// The drop's arcs: each one's prediction (the flight model, or a first fall's local curve),
// its refit, the gate its samples are followed with and the noise they show.
#include "detect/flight_arcs.h"
#include "detect/detector_stats.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bouncefit {

using detector_stats::Median;
using detector_stats::ParabolaAt;

FlightArcs::FlightArcs(const FlightFollowerConfig& config, const DetectorScene& scene)
    : config_(config), scene_(scene) {}

std::vector<FlightArcData> FlightArcs::Data() const {
  std::vector<FlightArcData> out;
  for (const auto& a : arcs_) {
    FlightArcData d;
    d.held_before_apex = a.held;
    for (const auto& s : a.samples) d.samples.push_back({s.t, s.x, s.y});
    out.push_back(std::move(d));
  }
  return out;
}

void FlightArcs::TakeFits(const FlightFit& flight) {
  for (size_t j = 0; j < arcs_.size() && j < flight.arcs.size(); ++j) {
    arcs_[j].fit = flight.arcs[j];
    arcs_[j].fit_ok = true;
    arcs_[j].u_sigma = flight.u_apex_sigma[j];
  }
}

const FlightImpact* FlightArcs::ImpactBeforeCurrent() const {
  if (arcs_.size() < 2) return nullptr;
  const size_t j = arcs_.size() - 2;  // impacts[j] lies between arcs j and j + 1
  if (j >= scene_.calibration().impacts.size() || !scene_.calibration().impacts[j].ok) return nullptr;
  return &scene_.calibration().impacts[j];
}

void FlightArcs::RescaleTime(double k) {
  for (auto& a : arcs_) {
    for (auto& q : a.samples) q.t *= k;
    a.fit.t_apex *= k;
    a.fit.vw /= k;
    a.fit_ok = false;
  }
}

bool FlightArcs::Predict(const DetectorArc& arc, double t, double* u, double* w,
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

void FlightArcs::Refit(DetectorArc& arc) const {
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
  const FlightImpact* began = ImpactBeforeCurrent();
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

double FlightArcs::ScaleGatePx(const DetectorArc& arc, double t) const {
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

double FlightArcs::SidewaysSpeed(const DetectorArc& arc) const {
  if (scene_.calibrated() && arc.fit_ok) return arc.fit.vw;
  const auto& q = arc.samples;
  if (q.size() < 2) return 0;
  const DetectorSample& a = q[q.size() >= 4 ? q.size() - 4 : 0];
  const DetectorSample& b = q.back();
  return b.t > a.t ? (Floor(b) - Floor(a)) / (b.t - a.t) : 0;
}

double FlightArcs::FollowGate(const DetectorArc& arc, double t, double v_down,
                              double gap_frames) const {
  double gate = scene_.FollowGate(v_down, gap_frames);
  if (arc.samples.size() < 4 || !scene_.calibrated()) gate += 2 * scene_.Gate();
  // Until the drop's noise is measured, an arc whose own samples scatter more than assumed
  // (a smeared ball at 20-30 fps is located to pixels, not tenths) is followed with its scatter.
  if (!scene_.sigma_measured()) gate = std::max(gate, scene_.config().gate_sigmas * Scatter(arc));
  gate += ScaleGatePx(arc, t);
  return gate;
}

double FlightArcs::Scatter(const DetectorArc& arc) const {
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
