#include "detect/flight_model.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bouncefit {
namespace {

constexpr double kHalfPi = std::numbers::pi / 2;

double LogCosh(double x) { return x + std::log1p(std::exp(-2 * x)) - std::numbers::ln2; }
double LogSec(double x) {
  x = std::min(x, kHalfPi - 1e-9);  // the ball cannot rise longer than this: a steep wall
  return -std::log(std::cos(x));
}

}  // namespace

double FlightDrop(double gravity_px, double drag_per_px, double tau) {
  const double g = gravity_px, k = drag_per_px;
  const double a = std::sqrt(g * std::abs(k));
  const double x = a * std::abs(tau);
  if (x < 1e-4 || !(g > 0)) {
    const double s = tau > 0 ? -1.0 : 1.0;
    return 0.5 * g * tau * tau + s * g * g * k * tau * tau * tau * tau / 12;
  }
  const double ak = std::abs(k);
  const bool falling = tau > 0;
  const bool cosh_branch = (k > 0) == falling;
  return (cosh_branch ? LogCosh(x) : LogSec(x)) / ak;
}

double FlightVelocityDown(double gravity_px, double drag_per_px, double tau) {
  const double g = gravity_px, k = drag_per_px;
  const double a = std::sqrt(g * std::abs(k));
  const double x = a * std::abs(tau);
  if (x < 1e-4 || !(g > 0)) {
    const double s = tau > 0 ? -1.0 : 1.0;
    return g * tau + s * g * g * k * tau * tau * tau / 3;
  }
  const double vt = std::sqrt(g / std::abs(k));
  const bool falling = tau > 0;
  const bool tanh_branch = (k > 0) == falling;
  const double speed = vt * (tanh_branch ? std::tanh(x) : std::tan(std::min(x, kHalfPi - 1e-9)));
  return falling ? speed : -speed;
}

double AlongDown(double x, double y, double roll_rad) {
  return x * std::sin(roll_rad) + y * std::cos(roll_rad);
}
double AlongFloor(double x, double y, double roll_rad) {
  return x * std::cos(roll_rad) - y * std::sin(roll_rad);
}

void FlightPosition(const FlightGlobals& g, const FlightArcParams& a, bool held_before_apex,
                    double t, double* x, double* y) {
  double tau = t - a.t_apex;
  if (held_before_apex && tau < a.lead_s) tau = a.lead_s;  // still in the hand
  const double u = a.u_apex + FlightDrop(g.gravity_px, g.drag_per_px, tau);
  const double w = a.w_apex + a.vw * tau;
  const double s = std::sin(g.roll_rad), c = std::cos(g.roll_rad);
  *x = u * s + w * c;
  *y = u * c - w * s;
}

double FlightTopU(const FlightGlobals& g, const FlightArcParams& a, bool held_before_apex) {
  if (!held_before_apex || !(a.lead_s > 0)) return a.u_apex;
  return a.u_apex + FlightDrop(g.gravity_px, g.drag_per_px, a.lead_s);
}

double FlightTopT(const FlightArcParams& a, bool held_before_apex) {
  return held_before_apex && a.lead_s > 0 ? a.t_apex + a.lead_s : a.t_apex;
}

FlightArcParams InitialArcParams(const FlightArcData& arc, const FlightGlobals& g) {
  FlightArcParams p;
  const auto& s = arc.samples;
  if (s.empty()) return p;
  std::vector<double> t, u, w;
  for (const auto& q : s) {
    t.push_back(q.t);
    u.push_back(AlongDown(q.x, q.y, g.roll_rad));
    w.push_back(AlongFloor(q.x, q.y, g.roll_rad));
  }
  size_t first = 0;
  if (arc.held_before_apex && s.size() >= 4) {
    // Skip the hold: samples within a pixel and a half of the first ones.
    std::vector<double> head(u.begin(), u.begin() + std::min<size_t>(5, u.size()));
    std::nth_element(head.begin(), head.begin() + head.size() / 2, head.end());
    const double hold = head[head.size() / 2];
    while (first + 1 < u.size() && u[first + 1] - hold < 1.5) ++first;
    // `first` is the last hold sample; the fall starts after it.
    if (u.size() - first < 3) first = 0;
  }
  const size_t n = u.size() - first;
  double tm = 0;
  for (size_t i = first; i < u.size(); ++i) tm += t[i];
  tm /= static_cast<double>(n);
  if (n >= 3 || (n >= 2 && g.gravity_px > 0)) {
    const bool fixed_curvature = g.gravity_px > 0;
    const int cols = fixed_curvature ? 2 : 3;
    Eigen::MatrixXd a(static_cast<Eigen::Index>(n), cols);
    Eigen::VectorXd b(static_cast<Eigen::Index>(n));
    for (size_t i = first; i < u.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i - first);
      const double dt = t[i] - tm;
      a(r, 0) = 1;
      a(r, 1) = dt;
      if (fixed_curvature)
        b(r) = u[i] - 0.5 * g.gravity_px * dt * dt;
      else {
        a(r, 2) = dt * dt;
        b(r) = u[i];
      }
    }
    Eigen::VectorXd c = a.colPivHouseholderQr().solve(b);
    const double c2 = fixed_curvature ? 0.5 * g.gravity_px : c(2);
    if (c2 > 0) {
      const double dta = -c(1) / (2 * c2);
      p.t_apex = tm + dta;
      p.u_apex = c(0) - c(1) * c(1) / (4 * c2);
    } else {
      p.t_apex = tm;
      p.u_apex = *std::min_element(u.begin() + static_cast<long>(first), u.end());
    }
  } else {
    p.t_apex = tm;
    p.u_apex = u[first];
  }
  // Horizontal: a line through the moving samples.
  if (n >= 2) {
    double st = 0, sw = 0, stt = 0, stw = 0;
    for (size_t i = first; i < u.size(); ++i) {
      const double dt = t[i] - p.t_apex;
      st += dt;
      sw += w[i];
      stt += dt * dt;
      stw += dt * w[i];
    }
    const double nn = static_cast<double>(n);
    const double den = nn * stt - st * st;
    if (std::abs(den) > 1e-12) {
      p.vw = (nn * stw - st * sw) / den;
      p.w_apex = (sw - p.vw * st) / nn;
    } else {
      p.w_apex = sw / nn;
    }
  } else {
    p.w_apex = w[first];
  }
  return p;
}

namespace {

// Parameter layout: [G, k, roll, (t_apex, u_apex, w_apex, vw, lead_s) per arc].
constexpr int kGlobals = 3;
constexpr int kPerArc = 5;

struct Problem {
  const std::vector<FlightArcData>* arcs;
  std::vector<int> row_start;  // first residual row of each arc
  int rows = 0;

  FlightGlobals Globals(const Eigen::VectorXd& p) const { return {p(0), p(1), p(2)}; }
  static FlightArcParams Arc(const Eigen::VectorXd& p, size_t j) {
    const auto o = static_cast<Eigen::Index>(kGlobals + kPerArc * j);
    return {p(o), p(o + 1), p(o + 2), p(o + 3), p(o + 4)};
  }
  // Residuals (observed - model) of one arc into r at its rows.
  void ArcResiduals(const Eigen::VectorXd& p, size_t j, Eigen::VectorXd& r) const {
    const FlightGlobals g = Globals(p);
    const FlightArcParams a = Arc(p, j);
    const auto& arc = (*arcs)[j];
    int row = row_start[j];
    for (const auto& s : arc.samples) {
      double x, y;
      FlightPosition(g, a, arc.held_before_apex, s.t, &x, &y);
      r(row++) = s.x - x;
      r(row++) = s.y - y;
    }
  }
  void Residuals(const Eigen::VectorXd& p, Eigen::VectorXd& r) const {
    for (size_t j = 0; j < arcs->size(); ++j) ArcResiduals(p, j, r);
  }
};

double StepFor(int index, const Eigen::VectorXd& p) {
  if (index == 0) return 1e-6 * std::max(1.0, std::abs(p(0)));
  if (index == 1) return 1e-9;
  if (index == 2) return 1e-7;
  switch ((index - kGlobals) % kPerArc) {
    case 0: return 1e-7;
    case 1: return 1e-4;
    case 2: return 1e-4;
    case 3: return 1e-3;
    default: return 1e-7;
  }
}

// J^T J and J^T r of a Jacobian whose arc columns are zero outside their arc's rows
// ([start, start + len) of each column; a global column spans every row): products over the
// rows both columns share, none between two arcs. A dense product costs rows x columns^2 and
// was most of a detector's time on a drop of many arcs.
struct ColumnRows {
  int arc = -1;  // -1: a global column
  int start = 0, len = 0;
};

void NormalEquations(const Eigen::MatrixXd& jac, const Eigen::VectorXd& r,
                     const std::vector<ColumnRows>& cols, Eigen::MatrixXd* a, Eigen::VectorXd* b) {
  const auto nf = static_cast<Eigen::Index>(cols.size());
  a->setZero(nf, nf);
  b->resize(nf);
  for (Eigen::Index c1 = 0; c1 < nf; ++c1) {
    const ColumnRows& k1 = cols[static_cast<size_t>(c1)];
    (*b)(c1) = jac.col(c1).segment(k1.start, k1.len).dot(r.segment(k1.start, k1.len));
    for (Eigen::Index c2 = 0; c2 <= c1; ++c2) {
      const ColumnRows& k2 = cols[static_cast<size_t>(c2)];
      if (k1.arc >= 0 && k2.arc >= 0 && k1.arc != k2.arc) continue;
      const ColumnRows& rows = k1.arc >= 0 ? k1 : k2;
      const double v = jac.col(c1).segment(rows.start, rows.len)
                           .dot(jac.col(c2).segment(rows.start, rows.len));
      (*a)(c1, c2) = v;
      (*a)(c2, c1) = v;
    }
  }
}

}  // namespace

FlightFit FitFlight(const std::vector<FlightArcData>& arcs, const FlightGlobals& initial,
                    const std::vector<FlightArcParams>& initial_arcs,
                    const FlightFitOptions& options) {
  FlightFit fit;
  fit.globals = initial;
  if (arcs.empty()) return fit;
  Problem prob;
  prob.arcs = &arcs;
  for (const auto& a : arcs) {
    prob.row_start.push_back(prob.rows);
    prob.rows += 2 * static_cast<int>(a.samples.size());
  }
  fit.samples = prob.rows / 2;
  const int n_params = kGlobals + kPerArc * static_cast<int>(arcs.size());
  Eigen::VectorXd p(n_params);
  p(0) = initial.gravity_px;
  p(1) = initial.drag_per_px;
  p(2) = initial.roll_rad;
  for (size_t j = 0; j < arcs.size(); ++j) {
    const FlightArcParams a =
        j < initial_arcs.size() ? initial_arcs[j] : InitialArcParams(arcs[j], initial);
    const auto o = static_cast<Eigen::Index>(kGlobals + kPerArc * j);
    p(o) = a.t_apex;
    p(o + 1) = a.u_apex;
    p(o + 2) = a.w_apex;
    p(o + 3) = a.vw;
    p(o + 4) = arcs[j].held_before_apex ? a.lead_s : 0.0;
  }
  // Free parameters.
  std::vector<int> free;
  if (options.fit_gravity) free.push_back(0);
  if (options.fit_drag) free.push_back(1);
  if (options.fit_roll) free.push_back(2);
  for (size_t j = 0; j < arcs.size(); ++j) {
    const int o = kGlobals + kPerArc * static_cast<int>(j);
    const auto n = arcs[j].samples.size();
    if (n == 0) continue;
    free.push_back(o + 1);  // u_apex
    free.push_back(o + 2);  // w_apex
    if (n >= 2) free.push_back(o);  // t_apex
    if (n >= 3 && options.fit_horizontal_speed) free.push_back(o + 3);
    if (options.fit_release_lead && arcs[j].held_before_apex && n >= 6) free.push_back(o + 4);
  }
  const int nf = static_cast<int>(free.size());
  if (prob.rows < nf || nf == 0) return fit;

  auto arc_of = [](int index) { return index < kGlobals ? -1 : (index - kGlobals) / kPerArc; };
  std::vector<ColumnRows> column_rows;
  for (int idx : free) {
    const int arc = arc_of(idx);
    if (arc < 0)
      column_rows.push_back({-1, 0, prob.rows});
    else
      column_rows.push_back({arc, prob.row_start[static_cast<size_t>(arc)],
                             2 * static_cast<int>(arcs[static_cast<size_t>(arc)].samples.size())});
  }
  Eigen::VectorXd r(prob.rows), r2(prob.rows);
  prob.Residuals(p, r);
  double cost = r.squaredNorm();
  double lambda = 1e-3;
  Eigen::MatrixXd jac(prob.rows, nf);
  int it = 0;
  for (; it < options.max_iterations; ++it) {
    jac.setZero();
    for (int c = 0; c < nf; ++c) {
      const int idx = free[static_cast<size_t>(c)];
      const double h = StepFor(idx, p);
      Eigen::VectorXd pp = p, pm = p;
      pp(idx) += h;
      pm(idx) -= h;
      const int arc = arc_of(idx);
      if (arc < 0) {
        prob.Residuals(pp, r2);
        Eigen::VectorXd rm(prob.rows);
        prob.Residuals(pm, rm);
        jac.col(c) = (r2 - rm) / (2 * h);
      } else {
        const auto j = static_cast<size_t>(arc);
        const int start = prob.row_start[j];
        const int len = 2 * static_cast<int>(arcs[j].samples.size());
        Eigen::VectorXd rp(prob.rows), rm(prob.rows);
        prob.ArcResiduals(pp, j, rp);
        prob.ArcResiduals(pm, j, rm);
        jac.col(c).segment(start, len) =
            (rp.segment(start, len) - rm.segment(start, len)) / (2 * h);
      }
    }
    Eigen::MatrixXd a;
    Eigen::VectorXd b;
    NormalEquations(jac, r, column_rows, &a, &b);
    bool improved = false;
    double step_norm = 0;
    while (lambda < 1e12) {
      Eigen::MatrixXd am = a;
      for (int d = 0; d < nf; ++d) am(d, d) += lambda * std::max(a(d, d), 1e-12);
      const Eigen::VectorXd delta = am.ldlt().solve(-b);
      Eigen::VectorXd pn = p;
      for (int c = 0; c < nf; ++c) pn(free[static_cast<size_t>(c)]) += delta(c);
      if (!(pn(0) > 0)) {
        lambda *= 4;
        continue;
      }
      prob.Residuals(pn, r2);
      const double cn = r2.squaredNorm();
      if (std::isfinite(cn) && cn < cost) {
        const double gain = cost - cn;
        p = pn;
        r = r2;
        step_norm = gain / std::max(cost, 1e-30);
        cost = cn;
        lambda = std::max(lambda / 3, 1e-9);
        improved = true;
        break;
      }
      lambda *= 4;
    }
    if (!improved || step_norm < 1e-12) break;
  }
  fit.iterations = it;
  const int dof = std::max(1, prob.rows - nf);
  const double sigma2 = cost / dof;
  fit.rms_px = std::sqrt(cost / prob.rows);
  fit.globals = prob.Globals(p);
  for (size_t j = 0; j < arcs.size(); ++j) fit.arcs.push_back(Problem::Arc(p, j));
  // Covariance from the last Jacobian (at or next to the optimum).
  Eigen::MatrixXd jtj;
  Eigen::VectorXd jtr;
  NormalEquations(jac, r, column_rows, &jtj, &jtr);
  Eigen::MatrixXd cov = jtj.ldlt().solve(Eigen::MatrixXd::Identity(nf, nf));
  cov *= sigma2;
  fit.u_apex_sigma.assign(arcs.size(), 0.0);
  for (int c = 0; c < nf; ++c) {
    const int idx = free[static_cast<size_t>(c)];
    const double sd = std::sqrt(std::max(0.0, cov(c, c)));
    if (idx == 0) fit.gravity_sigma = sd;
    if (idx == 1) fit.drag_sigma = sd;
    if (idx == 2) fit.roll_sigma = sd;
    if (idx >= kGlobals && (idx - kGlobals) % kPerArc == 1)
      fit.u_apex_sigma[static_cast<size_t>(arc_of(idx))] = sd;
  }
  fit.ok = std::isfinite(cost) && fit.globals.gravity_px > 0;
  return fit;
}

FlightImpact IntersectArcs(const FlightGlobals& g, const FlightArcParams& a,
                           const FlightArcParams& b) {
  FlightImpact out;
  auto ua = [&](double t) { return a.u_apex + FlightDrop(g.gravity_px, g.drag_per_px, t - a.t_apex); };
  auto ub = [&](double t) { return b.u_apex + FlightDrop(g.gravity_px, g.drag_per_px, t - b.t_apex); };
  double lo = a.t_apex, hi = b.t_apex;
  if (!(hi > lo)) return out;
  if (!(ua(lo) - ub(lo) < 0) || !(ua(hi) - ub(hi) > 0)) return out;
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (ua(mid) - ub(mid) < 0)
      lo = mid;
    else
      hi = mid;
  }
  out.ok = true;
  out.t = 0.5 * (lo + hi);
  out.u = 0.5 * (ua(out.t) + ub(out.t));
  out.speed_in = std::abs(FlightVelocityDown(g.gravity_px, g.drag_per_px, out.t - a.t_apex));
  out.speed_out = std::abs(FlightVelocityDown(g.gravity_px, g.drag_per_px, out.t - b.t_apex));
  return out;
}

}  // namespace bouncefit
