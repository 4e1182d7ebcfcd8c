// transfer_bench: the transfer matrix (docs/FIT.md "Transfer"). A ball whose restitution falls with impact
// speed (synth's point mass, e(v) = e0 - k v, drag) is dropped from one height; its recorded
// heights are fitted; the fitted ball is then predicted from the other height (ensemble mean,
// as `bouncefit predict` does) and compared with the truth on every bounce of 2 cm or more:
// within max(5 mm, 3%), and no divergence.
//
//   transfer_bench [--balls pingpong,wiffle,softball,airball] [--designs restitution,boost]
//                  [--evals 40] [--objective drop|segments] [--members 8] [--threads 0]
//                  [--at-turn] [--flight-weight 1]
//
// The fit sees the recorded heights >= 1 cm and, weighted by --flight-weight (m/s; 0: off),
// the flight times between the true impacts (fit/fit_objective.h's timing).
//
// Designs, each fitted with the same Levenberg-Marquardt stage and budget:
//   restitution  the soft ball's restitution law (rebound_restitution, _per_mps, drag),
//                started from the point mass's fit (fit/restitution_fit.h); the rebound at
//                touch, or with --at-turn at the contact's deepest point;
//   boost        the paper's boost on top of Bullet's rebound (rebound_boost, _per_mps,
//                drag), started from the ball's stored table;
//   point-mass   the quick model alone (stage 1 of the restitution design), beside them.
// Prints one row per ball, direction and design; the baseline is the point mass in the same
// run.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "fit/drop_ensemble.h"
#include "fit/least_squares_search.h"
#include "fit/restitution_fit.h"
#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"
#include "model/soft_ball_model.h"

using namespace bouncefit;

namespace {

struct Args {
  std::vector<std::string> balls = {"pingpong", "wiffle", "softball", "airball"};
  std::vector<std::string> designs = {"restitution", "boost"};
  int evals = 40;
  bool segments = false;  // as the session's default objective: one free drop
  int members = 8;
  int threads = 0;
  bool at_turn = false;
  double flight_weight = 1.0;
  std::string start = "defaults";  // the restitution design's other coefficients
};

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// Restitution slopes like real balls' (a ping-pong ball loses ~0.02 per m/s; softer and
// heavier balls more), the presets' e0 and Cd otherwise.
BallPreset TruthBall(const std::string& name) {
  BallPreset b = ResolveBallPreset(name, 0, 0);
  if (name == "pingpong") b.restitution = 0.92, b.restitution_per_mps = 0.02;
  if (name == "wiffle") b.restitution = 0.62, b.restitution_per_mps = 0.03;
  if (name == "softball") b.restitution = 0.42, b.restitution_per_mps = 0.03;
  if (name == "airball") b.restitution = 0.80, b.restitution_per_mps = 0.02;
  return b;
}

PointMassDropResult TruthDrop(const BallPreset& ball, double drop) {
  PointMassDropConfig c;
  c.ball = ball;
  c.drop_height_m = drop;
  c.end_time_s = 30;
  return SimulatePointMassDrop(c);
}

// Largest |simulated - true| impact time over impacts 2..6 (through the 5th bounce), both
// counted from their first impact, ms; impacts after the simulation's last (its bounces
// stop below 1 cm, the truth's go on) are not compared; NaN when it made fewer than two.
double TimingErrorMs(const std::vector<double>& truth, const std::vector<double>& sim) {
  if (sim.size() < 2) return NAN;
  double worst = 0;
  for (size_t i = 1; i <= 5 && i < truth.size() && i < sim.size(); ++i) {
    worst = std::max(worst, std::abs((sim[i] - sim[0]) - (truth[i] - truth[0])));
  }
  return 1000 * worst;
}

std::vector<double> TruthHeights(const BallPreset& ball, double drop, double min_m) {
  const auto r = TruthDrop(ball, drop);
  std::vector<double> h;
  for (size_t i = 1; i < r.apex_heights_m.size() && r.apex_heights_m[i] >= min_m; ++i)
    h.push_back(r.apex_heights_m[i]);
  return h;
}

struct Verdict {
  bool ok = false;         // every bounce >= 2 cm within max(5 mm, 3%), no divergence
  double worst_pct = 0;    // largest |error| in % of the truth
  int bounces = 0;
  std::string errors;      // per bounce, %
};

Verdict Judge(const std::vector<double>& truth, const DropEnsemble& e) {
  Verdict v;
  if (!e.ok) {
    v.errors = "diverged: " + e.failure;
    return v;
  }
  v.ok = true;
  for (size_t i = 0; i < truth.size() && truth[i] >= 0.02; ++i) {
    ++v.bounces;
    const double sim = i < e.mean_m.size() ? e.mean_m[i] : 0;
    const double err = sim - truth[i];
    const double pct = 100 * err / truth[i];
    v.worst_pct = std::max(v.worst_pct, std::abs(pct));
    if (std::abs(err) > std::max(0.005, 0.03 * truth[i])) v.ok = false;
    v.errors += fmt::format("{}{:+.1f}", v.errors.empty() ? "" : " ", pct);
  }
  return v;
}

double Rms(const std::vector<double>& truth, const std::vector<double>& sim) {
  return RmsResidual(truth, sim);
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "transfer_bench: %s needs a value\n", k.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (k == "--balls") a.balls = Split(next());
    else if (k == "--designs") a.designs = Split(next());
    else if (k == "--evals") a.evals = std::stoi(next());
    else if (k == "--objective") a.segments = next() == "segments";
    else if (k == "--members") a.members = std::stoi(next());
    else if (k == "--threads") a.threads = std::stoi(next());
    else if (k == "--at-turn") a.at_turn = true;
    else if (k == "--flight-weight") a.flight_weight = std::stod(next());
    else if (k == "--start") a.start = next();
    else if (k == "--help" || k == "-h") {
      std::printf(
          "transfer_bench [--balls pingpong,wiffle,softball,airball] [--designs "
          "restitution,boost] [--evals 40] [--objective drop|segments] [--members 8] "
          "[--threads 0] [--at-turn] [--flight-weight 1] [--start defaults|table]\nFits a drop of synth's physics from 1.0 m and 1.6 m, predicts the "
          "other height; prints errors in %% of the truth per bounce >= 2 cm.\n");
      return 0;
    } else {
      std::fprintf(stderr, "transfer_bench: unknown argument %s (see --help)\n", k.c_str());
      return 2;
    }
  }
  std::printf("| ball | fit -> predict | design | fit RMS mm (fitted objective / ensemble mean) "
              "| predicted, error per bounce >= 2 cm (%%) | worst %% | holds | simulations | "
              "wall s | impacts 2-6, worst ms off (fitted / predicted) | diverges from |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  int holds = 0, rows = 0;
  for (const auto& name : a.balls) {
    const BallPreset truth_ball = TruthBall(name);
    const BallPreset ball = ResolveBallPreset(name, 0, 0);
    SoftBallModelConfig config;
    config.rebound_at_touch = !a.at_turn;
    SoftBallModel soft(ball, config);
    PointMassModel point_mass(ball);
    // The boost design starts from the ball's stored table (fitted with the boost); the
    // restitution design from the model's defaults (the table's stiff contacts were chosen
    // to make Bullet itself rebound; the airball's diverges below 0.3 m).
    CoefficientValues table, defaults;
    if (const auto t = SoftBallPresetTable(name)) table = t->values;
    for (const auto& s : soft.Coefficients()) defaults[s.name] = s.default_value;
    for (const auto& [fit_h, pred_h] : {std::pair{1.0, 1.6}, std::pair{1.6, 1.0}}) {
      const std::vector<double> recorded = TruthHeights(truth_ball, fit_h, 0.01);
      const std::vector<double> target = TruthHeights(truth_ball, pred_h, 0.02);
      FitProblem p;
      p.model = &soft;
      p.fixed = table;
      p.recorded_m = recorded;
      p.recorded_flight_s =
          FlightTimes(TruthDrop(truth_ball, fit_h).impact_times_s, recorded.size());
      p.flight_weight_mps = a.flight_weight;
      p.segments = a.segments;
      p.simulation.drop_height_m = fit_h;
      p.simulation.duration_s = 1.5 * FreeFallApexTime(fit_h, recorded, recorded.size()) + 0.2;
      p.simulation.min_bounce_height_m = 0.005;
      SearchOptions so;
      so.threads = a.threads;
      so.max_evaluations = a.evals;
      SimulationOptions pred;
      pred.drop_height_m = pred_h;
      pred.min_bounce_height_m = 0.01;
      pred.duration_s = 6 + 10 * std::sqrt(pred_h);
      SimulationOptions fitted_drop = pred;
      fitted_drop.drop_height_m = fit_h;
      DropEnsembleOptions eo;
      eo.members = a.members;
      eo.threads = a.threads;
      // Stage 1 once per input: the point mass's row, and the restitution design's start.
      const auto t0 = std::chrono::steady_clock::now();
      RestitutionFitOptions ro;
      ro.segments = a.segments;
      ro.max_evaluations = a.evals;
      const bool want_restitution =
          std::find(a.designs.begin(), a.designs.end(), "restitution") != a.designs.end();
      RestitutionFit rf;
      if (want_restitution) {
        FitProblem rp = p;
        rp.fixed = a.start == "table" && !table.empty() ? table : defaults;
        rf = FitRestitutionCurve(rp, point_mass, so, ro);
      }
      const double restitution_wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::vector<std::string> designs = a.designs;
      if (want_restitution) designs.push_back("point-mass");
      for (const auto& design : designs) {
        const BallModel* model = &soft;
        CoefficientValues values;
        double fitted_rms = 0, wall = 0;
        int sims = 0;
        if (design == "restitution") {
          values = rf.soft.values;
          fitted_rms = rf.soft.rms_m;
          sims = rf.soft.evaluations;
          wall = restitution_wall;
        } else if (design == "point-mass") {
          model = &point_mass;
          values = rf.point_mass.values;
          fitted_rms = rf.point_mass.rms_m;
          sims = rf.point_mass.evaluations;
        } else if (design == "boost") {
          const auto t1 = std::chrono::steady_clock::now();
          FitProblem bp = p;
          const double cd = table.count("drag") ? table.at("drag") : ball.drag_coefficient;
          for (auto s : soft.Coefficients()) {
            if (s.name == "drag") s.lower = cd / 1.6, s.upper = cd * 1.6;
            if (s.name == "rebound_boost" || s.name == "rebound_boost_per_mps" || s.name == "drag")
              bp.free.push_back(s);
          }
          LeastSquaresOptions ls;
          ls.fd_step = 0.02;
          ls.max_iterations = 8;
          ls.min_relative_gain = 1e-3;
          const SearchResult r = LeastSquaresSearch(bp, table, so, ls);
          values = r.values;
          fitted_rms = r.rms_m;
          sims = r.evaluations;
          wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
        } else {
          std::fprintf(stderr, "transfer_bench: unknown design %s\n", design.c_str());
          return 2;
        }
        const DropEnsemble at_fit = SimulateDropEnsemble(*model, values, fitted_drop, eo);
        const DropEnsemble e = SimulateDropEnsemble(*model, values, pred, eo);
        const Verdict v = Judge(target, e);
        const double timing_fit = TimingErrorMs(TruthDrop(truth_ball, fit_h).impact_times_s,
                                                SimulateSafely(*model, values, fitted_drop).impact_times_s);
        const double timing_pred = TimingErrorMs(TruthDrop(truth_ball, pred_h).impact_times_s,
                                                 SimulateSafely(*model, values, pred).impact_times_s);
        // Safe wherever a user may drop it (0.3-2 m).
        const std::string unsafe = UnsafeDrop(*model, values, {0.3, 2.0}, a.threads);
        ++rows;
        holds += v.ok && unsafe.empty();
        std::printf("| %s | %.1f -> %.1f m | %s | %.1f / %.1f | %s | %.1f | %s | %d | %.1f | %.1f / %.1f | %s |\n",
                    name.c_str(), fit_h, pred_h, design.c_str(), fitted_rms * 1000,
                    at_fit.ok ? Rms(recorded, at_fit.mean_m) * 1000 : NAN, v.errors.c_str(),
                    v.worst_pct, v.ok && unsafe.empty() ? "yes" : "no", sims, wall, timing_fit, timing_pred,
                    unsafe.empty() ? "-" : unsafe.c_str());
        std::fflush(stdout);
      }
    }
  }
  std::printf("transfer holds in %d of %d rows\n", holds, rows);
  return 0;
}
