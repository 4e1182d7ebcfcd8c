#include "detect/calibrator.h"
#include "detect/detector_stats.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bouncefit {
namespace {

// Index of a held arc's last sample still in the hand (within 1.5 px of the first); 0 for an
// arc not held.
size_t HoldEnd(const FlightArcData& arc) {
  const auto& s = arc.samples;
  size_t first = 0;
  if (arc.held_before_apex && s.size() >= 4) {
    const double x0 = s.front().x, y0 = s.front().y;
    while (first + 1 < s.size() && std::hypot(s[first + 1].x - x0, s[first + 1].y - y0) < 1.5)
      ++first;
  }
  return first;
}

// Image acceleration (px/s^2) of an arc from quadratic fits of x(t) and y(t), skipping a
// hold at its start. False with fewer than 5 moving samples.
bool ArcAcceleration(const FlightArcData& arc, double* ax, double* ay, int* n_used) {
  const auto& s = arc.samples;
  const size_t first = HoldEnd(arc);
  const size_t n = s.size() - first;
  if (n < 5) return false;
  double tm = 0;
  for (size_t i = first; i < s.size(); ++i) tm += s[i].t;
  tm /= static_cast<double>(n);
  Eigen::MatrixXd a(static_cast<Eigen::Index>(n), 3);
  Eigen::MatrixXd b(static_cast<Eigen::Index>(n), 2);
  for (size_t i = first; i < s.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i - first);
    const double dt = s[i].t - tm;
    a(r, 0) = 1;
    a(r, 1) = dt;
    a(r, 2) = dt * dt;
    b(r, 0) = s[i].x;
    b(r, 1) = s[i].y;
  }
  const Eigen::MatrixXd c = a.colPivHouseholderQr().solve(b);
  *ax = 2 * c(2, 0);
  *ay = 2 * c(2, 1);
  *n_used = static_cast<int>(n);
  return std::isfinite(*ax) && std::isfinite(*ay);
}

// The arc's own vertex lies within its samples or just before them (a fall from rest whose
// first frames were missed): its shape pins the start of the fall.
bool ApexInside(const FlightArcData& arc, const FlightGlobals& g) {
  if (arc.samples.size() < 3) return false;
  const FlightArcParams p = InitialArcParams(arc, g);
  return p.t_apex > arc.samples.front().t - 0.1 && p.t_apex < arc.samples.back().t;
}

// An arc's own image acceleration (ArcAcceleration), once per calibration: it both screens
// the arcs and starts the shared fit.
struct ArcAccel {
  bool ok = false;
  double ax = 0, ay = 0;  // px/s^2
  int n = 0;              // samples it rests on
};

// The accelerations of arcs k where use(k) holds, summed weighted by their samples: the pooled
// acceleration is (sx, sy) / n (n 0: none).
struct PooledAccel {
  double sx = 0, sy = 0;
  int n = 0;
};
template <typename Use>
PooledAccel Pool(const std::vector<ArcAccel>& accels, Use use) {
  PooledAccel p;
  for (size_t k = 0; k < accels.size(); ++k) {
    const ArcAccel& a = accels[k];
    if (!a.ok || !use(k)) continue;
    p.sx += a.ax * a.n;
    p.sy += a.ay * a.n;
    p.n += a.n;
  }
  return p;
}

// An arc that is not a free flight: the ball rolling or sliding at the end of a drop (the
// "arc" of a rolling ball is flat), or moved by a hand. Its own acceleration, from 5 samples or
// more, is under half the median of the arcs' that measure one, of 3 arcs or more. It would
// pull the shared gravity down: a tennis clip's last calibration went from 395 to 263 px/m
// when a 6-sample roll joined it. Drops it from all three lists.
void DropArcsNotInFreeFall(std::vector<FlightArcData>* arcs, std::vector<size_t>* index,
                           std::vector<ArcAccel>* accels) {
  std::vector<double> measured;
  for (const auto& a : *accels)
    if (a.ok) measured.push_back(std::hypot(a.ax, a.ay));
  if (measured.size() < 3) return;
  std::nth_element(measured.begin(), measured.begin() + measured.size() / 2, measured.end());
  const double median = measured[measured.size() / 2];
  std::vector<FlightArcData> kept;
  std::vector<size_t> kept_index;
  std::vector<ArcAccel> kept_accels;
  for (size_t k = 0; k < arcs->size(); ++k) {
    const ArcAccel& a = (*accels)[k];
    if (a.ok && std::hypot(a.ax, a.ay) < 0.5 * median) continue;
    kept.push_back(std::move((*arcs)[k]));
    kept_index.push_back((*index)[k]);
    kept_accels.push_back(a);
  }
  *arcs = std::move(kept);
  *index = std::move(kept_index);
  *accels = std::move(kept_accels);
}

// An arc whose samples lie more than a ball's diameter off its own fit (RMS) is no free
// flight: what the tracker took for the ball held was something else and the ball's fall a
// streak it saw once (20 fps), or a hand carried it. It must not decide the globals with the
// arcs that are flights (the scale 20% off, and with it every later arc's prediction and
// gate): the fit again without the worst such arc, when another arc that is a flight remains.
FlightFit WithoutArcFarOffItsFit(const FlightFit& fit, double radius_px, const FlightFitOptions& opt,
                                 std::vector<FlightArcData>* arcs, std::vector<size_t>* index,
                                 std::vector<ArcAccel>* accels) {
  const double limit = std::max(10.0, 2 * radius_px);
  std::vector<double> rms(arcs->size(), 0);
  for (size_t k = 0; k < arcs->size(); ++k) {
    const FlightArcData& a = (*arcs)[k];
    double ss = 0;
    for (const auto& q : a.samples) {
      double x, y;
      FlightPosition(fit.globals, fit.arcs[k], a.held_before_apex, q.t, &x, &y);
      ss += (x - q.x) * (x - q.x) + (y - q.y) * (y - q.y);
    }
    rms[k] = a.samples.empty() ? 0 : std::sqrt(ss / (2.0 * a.samples.size()));
  }
  const size_t worst = static_cast<size_t>(std::max_element(rms.begin(), rms.end()) - rms.begin());
  const bool flight_left = std::any_of(rms.begin(), rms.end(), [&](double r) { return r <= limit; });
  if (arcs->size() < 2 || rms[worst] <= limit || !flight_left) return fit;
  std::vector<FlightArcData> flights = *arcs;
  std::vector<FlightArcParams> init = fit.arcs;
  const auto at = static_cast<long>(worst);
  flights.erase(flights.begin() + at);
  init.erase(init.begin() + at);
  FlightFitOptions o = opt;
  o.fit_drag = opt.fit_drag && (flights.size() >= 2 || flights[0].held_before_apex);
  FlightFit again = FitFlight(flights, fit.globals, init, o);
  if (!again.ok) return fit;
  *arcs = std::move(flights);
  index->erase(index->begin() + at);
  accels->erase(accels->begin() + at);
  return again;
}

// Where a held arc's fall, bent by gravity g, crosses the hand: its vertex from the moving
// samples, and the release that many seconds after it (before it: tossed up). False when fewer
// than 3 samples move or they fall less than min_fall_px below the hand (a hop of a ball at
// rest, taken for a hold and a release, says nothing of a hand's push).
bool ReleaseStart(const FlightArcData& arc, const FlightGlobals& g, double min_fall_px,
                  FlightArcParams* out) {
  const FlightArcParams& current = *out;
  std::vector<double> t, u;
  for (const auto& q : arc.samples) {
    t.push_back(q.t);
    u.push_back(AlongDown(q.x, q.y, g.roll_rad));
  }
  const size_t last_held = HoldEnd(arc), first = last_held + 1;
  if (last_held == 0 || first + 3 > u.size() || !(g.gravity_px > 0)) return false;
  const double u_hand = detector_stats::Median({u.begin(), u.begin() + static_cast<long>(first)});
  if (*std::max_element(u.begin() + static_cast<long>(first), u.end()) - u_hand < min_fall_px)
    return false;
  // u = c0 + c1 dt + G/2 dt^2 through the moving samples (dt from their mean time).
  double tm = 0;
  for (size_t i = first; i < u.size(); ++i) tm += t[i];
  tm /= static_cast<double>(u.size() - first);
  double sd = 0, sdd = 0, sr = 0, sdr = 0, n = 0;
  for (size_t i = first; i < u.size(); ++i) {
    const double dt = t[i] - tm, r = u[i] - 0.5 * g.gravity_px * dt * dt;
    sd += dt, sdd += dt * dt, sr += r, sdr += dt * r, n += 1;
  }
  const double den = n * sdd - sd * sd;
  if (!(den > 0)) return false;
  const double c1 = (n * sdr - sd * sr) / den, c0 = (sr - c1 * sd) / n;
  FlightArcParams p = current;
  p.t_apex = tm - c1 / g.gravity_px;
  p.u_apex = c0 - c1 * c1 / (2 * g.gravity_px);
  const double lead = std::sqrt(2 * std::max(0.0, u_hand - p.u_apex) / g.gravity_px);
  p.lead_s = p.t_apex > t[first] ? -lead : lead;  // rising at first: tossed up
  p.w_apex = current.w_apex + current.vw * (p.t_apex - current.t_apex);
  *out = p;
  return true;
}

// Each held arc's release speed fitted too, kept only when it explains far more of the arcs
// than one more parameter per arc explains of noise: a drop from rest keeps its from-rest
// fit (freed, its speed trades with drag: a ping-pong ball's scale 2.5% off).
// `accels` are the arcs' own (ArcAcceleration), in the same order.
FlightFit WithReleaseSpeed(const std::vector<FlightArcData>& arcs,
                           const std::vector<ArcAccel>& accels, const FlightFit& from_rest,
                           double min_fall_px, FlightFitOptions opt) {
  // The fit is local: it starts from each held arc's release under a gravity. The from-rest
  // fit reads a push as stronger gravity (a 0.6 m/s push, 10% on a short first rebound) and
  // may leave the fit in a worse minimum than from rest; the rebounds' own bend does not.
  std::vector<FlightGlobals> gravities{from_rest.globals};
  const PooledAccel rebounds = Pool(accels, [&](size_t k) { return !arcs[k].held_before_apex; });
  // (Tried only when it differs: a drop from rest bends alike before and after its impact.)
  const double rebound_gravity =
      rebounds.n > 0 ? std::hypot(rebounds.sx, rebounds.sy) / rebounds.n : 0;
  if (rebounds.n > 0 && std::abs(rebound_gravity / from_rest.globals.gravity_px - 1) > 0.02) {
    gravities.push_back(from_rest.globals);
    gravities.back().gravity_px = rebound_gravity;
  }
  opt.fit_release_lead = true;
  FlightFit pushed;
  int freed = 0;
  for (const FlightGlobals& g : gravities) {
    std::vector<FlightArcParams> start = from_rest.arcs;
    int n_freed = 0;
    for (size_t j = 0; j < arcs.size(); ++j)
      if (arcs[j].held_before_apex && ReleaseStart(arcs[j], g, min_fall_px, &start[j])) ++n_freed;
    if (n_freed == 0) continue;
    const FlightFit fit = FitFlight(arcs, g, start, opt);
    if (fit.ok && (!pushed.ok || fit.rms_px < pushed.rms_px)) pushed = fit, freed = n_freed;
  }
  if (freed == 0 || !pushed.ok) return from_rest;
  const double rows = 2.0 * pushed.samples;
  const double cost_rest = from_rest.rms_px * from_rest.rms_px * rows;
  const double cost_pushed = pushed.rms_px * pushed.rms_px * rows;
  const double params = 3.0 + 5.0 * static_cast<double>(arcs.size());
  const double sigma2 = cost_pushed / std::max(1.0, rows - params);
  constexpr double kSigmas = 5;
  return cost_rest - cost_pushed > kSigmas * kSigmas * sigma2 * freed ? pushed : from_rest;
}

}  // namespace

bool CalibratorConfig::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!(g_mps2 > 0)) return fail("g must be > 0 m/s^2");
  if (ball_diameter_m < 0 || !std::isfinite(ball_diameter_m))
    return fail("ball diameter must be >= 0 m");
  if (px_per_m < 0 || !std::isfinite(px_per_m)) return fail("px per metre must be >= 0");
  if (drop_height_m < 0 || !std::isfinite(drop_height_m))
    return fail("drop height must be >= 0 m");
  if (px_per_m > 0 && drop_height_m > 0)
    return fail("give either a px per metre scale or a drop height, not both");
  if (max_arcs < 1) return fail("max arcs must be >= 1");
  if (min_arc_samples < 3) return fail("min arc samples must be >= 3");
  if (!(max_free_fall_rel_sigma > 0)) return fail("max free-fall relative sigma must be > 0");
  return true;
}

Calibrator::Calibrator(CalibratorConfig config) : config_(config) {
  std::string error;
  if (!config_.IsValid(&error)) throw std::invalid_argument("calibrator: " + error);
}

FlightFit Calibrator::FitArcs(const std::vector<FlightArcData>& arcs,
                              const FlightGlobals& globals,
                              const std::vector<FlightArcParams>& initial) const {
  FlightFitOptions opt;
  opt.fit_gravity = opt.fit_drag = opt.fit_roll = false;
  std::vector<FlightArcParams> init = initial;
  for (size_t j = init.size(); j < arcs.size(); ++j)
    init.push_back(InitialArcParams(arcs[j], globals));
  // Arcs with fewer than three samples cannot tell their horizontal speed.
  bool short_arc = false;
  for (const auto& a : arcs) short_arc = short_arc || a.samples.size() < 3;
  if (short_arc && arcs.size() == 1) opt.fit_horizontal_speed = false;
  return FitFlight(arcs, globals, init, opt);
}

CalibrationResult Calibrator::Calibrate(const CalibrationInput& in) const {
  CalibrationResult res;
  Calibration& cal = res.calibration;
  cal.utime = in.utime;
  cal.radius_px = in.radius_px;

  // Arcs that decide the globals.
  std::vector<FlightArcData> chosen;
  std::vector<size_t> chosen_index;
  for (size_t j = 0; j < in.arcs.size() && static_cast<int>(chosen.size()) < config_.max_arcs;
       ++j) {
    if (static_cast<int>(in.arcs[j].samples.size()) >= config_.min_arc_samples) {
      chosen.push_back(in.arcs[j]);
      chosen_index.push_back(j);
    }
  }
  std::vector<ArcAccel> accels(chosen.size());
  for (size_t k = 0; k < chosen.size(); ++k)
    accels[k].ok = ArcAcceleration(chosen[k], &accels[k].ax, &accels[k].ay, &accels[k].n);
  DropArcsNotInFreeFall(&chosen, &chosen_index, &accels);

  FlightGlobals init;
  if (in.previous_globals && in.previous_globals->gravity_px > 0) {
    init = *in.previous_globals;
  } else {
    const PooledAccel all = Pool(accels, [](size_t) { return true; });
    if (all.n > 0) {
      init.gravity_px = std::hypot(all.sx, all.sy) / all.n;
      init.roll_rad = std::atan2(all.sx, all.sy);
    }
  }
  if (!config_.fit_drag) init.drag_per_px = 0;

  if (chosen.empty() || !(init.gravity_px > 0)) {
    res.problem = "no free-flight arc long enough to measure gravity yet";
  } else {
    std::vector<FlightArcParams> init_arcs;
    for (size_t c = 0; c < chosen.size(); ++c) {
      const size_t j = chosen_index[c];
      if (in.previous_arcs && j < in.previous_arcs->size())
        init_arcs.push_back((*in.previous_arcs)[j]);
      else
        init_arcs.push_back(InitialArcParams(chosen[c], init));
    }
    FlightFitOptions opt;
    // One arc seen from neither a hold nor its vertex (it entered the view falling) does
    // not tell gravity from drag: the fit trades one for the other (40% off seen on a
    // 0.16 s fall). Drag waits for a second arc.
    opt.fit_drag = config_.fit_drag && (chosen.size() >= 2 || chosen[0].held_before_apex ||
                                        ApexInside(chosen[0], init));
    FlightFit global = FitFlight(chosen, init, init_arcs, opt);
    // Drag must slow the ball: a negative fit is noise, refit without it.
    if (global.ok && global.globals.drag_per_px < 0) {
      FlightGlobals g0 = global.globals;
      g0.drag_per_px = 0;
      opt.fit_drag = false;
      global = FitFlight(chosen, g0, global.arcs, opt);
    }
    if (global.ok) global = WithoutArcFarOffItsFit(global, in.radius_px, opt, &chosen, &chosen_index, &accels);
    if (global.ok && config_.fit_release_speed && chosen.size() >= 2)
      global = WithReleaseSpeed(chosen, accels, global, 4 * in.radius_px, opt);
    if (!global.ok) {
      res.problem = "the free-flight fit failed";
    } else {
      // Every arc's apex with the globals fixed.
      std::vector<FlightArcParams> all_init;
      for (size_t j = 0; j < in.arcs.size(); ++j) {
        auto it = std::find(chosen_index.begin(), chosen_index.end(), j);
        if (it != chosen_index.end())
          all_init.push_back(global.arcs[static_cast<size_t>(it - chosen_index.begin())]);
        else if (in.previous_arcs && j < in.previous_arcs->size())
          all_init.push_back((*in.previous_arcs)[j]);
        else
          all_init.push_back(InitialArcParams(in.arcs[j], global.globals));
      }
      // Arcs are independent once the globals are fixed: one small fit each.
      FlightFit all;
      all.ok = true;  // the globals are known; an arc that cannot be fitted keeps its start
      all.globals = global.globals;
      for (size_t j = 0; j < in.arcs.size(); ++j) {
        const FlightFit one = FitArcs({in.arcs[j]}, global.globals, {all_init[j]});
        all.arcs.push_back(one.ok ? one.arcs[0] : all_init[j]);
        all.u_apex_sigma.push_back(one.ok ? one.u_apex_sigma[0] : 0.0);
        all.samples += one.samples;
      }
      all.gravity_sigma = global.gravity_sigma;
      all.drag_sigma = global.drag_sigma;
      all.roll_sigma = global.roll_sigma;
      all.rms_px = global.rms_px;
      res.flight = all;
      cal.gravity_px = all.globals.gravity_px;
      cal.drag_per_px = all.globals.drag_per_px;
      cal.roll_rad = all.globals.roll_rad;
      cal.roll_sigma_rad = global.roll_sigma;
      cal.free_fall_px_per_m = cal.gravity_px / config_.g_mps2;
      cal.samples = global.samples;
      cal.rms_px = global.rms_px;
      cal.px_per_m = cal.free_fall_px_per_m;
      cal.px_per_m_sigma = global.gravity_sigma / config_.g_mps2;
      cal.free_fall_sigma = cal.px_per_m_sigma;
      cal.method = "free-fall";
    }
  }

  // Floor: where consecutive arcs meet, weighted by how well the shorter arc is known.
  if (res.flight.arcs.size() == in.arcs.size()) {
    double sw = 0, su = 0, suu = 0;
    int count = 0;
    for (size_t j = 0; j + 1 < in.arcs.size(); ++j) {
      const FlightImpact imp =
          IntersectArcs(res.flight.globals, res.flight.arcs[j], res.flight.arcs[j + 1]);
      res.impacts.push_back(imp);
      if (!imp.ok) continue;
      const double w = static_cast<double>(std::min<size_t>(
          {in.arcs[j].samples.size(), in.arcs[j + 1].samples.size(), 10}));
      sw += w;
      su += w * imp.u;
      suu += w * imp.u * imp.u;
      ++count;
    }
    if (count > 0) {
      const double mean = su / sw;
      cal.has_floor = true;
      cal.floor_px = mean + in.radius_px;
      const double var = std::max(0.0, suu / sw - mean * mean);
      cal.floor_sigma_px = count >= 2 ? std::sqrt(var / (count - 1))
                                      : std::max(cal.rms_px, 0.05);
    }
  }
  if (!cal.has_floor && !in.rest_u_px.empty()) {
    std::vector<double> r = in.rest_u_px;
    std::nth_element(r.begin(), r.begin() + static_cast<long>(r.size() / 2), r.end());
    cal.has_floor = true;
    cal.floor_px = r[r.size() / 2] + in.radius_px;
    cal.floor_sigma_px = std::max(cal.rms_px, 0.05);
  }

  // The scale actually used for metres.
  if (config_.px_per_m > 0) {
    cal.px_per_m = config_.px_per_m;
    cal.px_per_m_sigma = 0;
    cal.method = "user";
  } else if (config_.drop_height_m > 0) {
    cal.px_per_m = 0;
    cal.method = "drop-height";
    if (cal.has_floor && !res.flight.arcs.empty()) {
      const double top =
          FlightTopU(res.flight.globals, res.flight.arcs[0], in.arcs[0].held_before_apex);
      const double h_px = cal.floor_centre_px() - top;
      if (h_px > 0) {
        cal.px_per_m = h_px / config_.drop_height_m;
        const double su0 =
            res.flight.u_apex_sigma.empty() ? 0.0 : res.flight.u_apex_sigma[0];
        cal.px_per_m_sigma = std::hypot(su0, cal.floor_sigma_px) / config_.drop_height_m;
      }
    }
  } else if ((!(cal.px_per_m > 0) || !cal.FreeFallMeasured(config_.max_free_fall_rel_sigma)) &&
             config_.ball_diameter_m > 0 && in.radius_px > 0) {
    cal.px_per_m = 2 * in.radius_px / config_.ball_diameter_m;
    cal.px_per_m_sigma = 0.05 * cal.px_per_m;  // edge blur and threshold: a few percent
    cal.method = "ball-diameter";
  }
  if (config_.ball_diameter_m > 0 && in.radius_px > 0 && cal.free_fall_px_per_m > 0)
    cal.gravity_over_size =
        cal.free_fall_px_per_m / (2 * in.radius_px / config_.ball_diameter_m);
  if (config_.ball_diameter_m > 0 && cal.px_per_m > 0 && in.radius_px > 0)
    cal.diameter_ratio = 2 * in.radius_px / cal.px_per_m / config_.ball_diameter_m;

  res.ok = cal.px_per_m > 0 && res.flight.ok;
  if (!res.ok && res.problem.empty()) res.problem = "no scale yet";
  return res;
}

}  // namespace bouncefit
