// A trial, measured and not adopted: the Bullet FEM (btDeformableBody, Neo-Hookean) ball
// measured against the criteria for adopting it, with the classic btSoftBody ball as the
// baseline of the same run. docs/journal/fem-trial.md holds the figures and the decision.
//
//   build/bench/fem_ball_bench [--section rebound|steps|smooth|cost|transfer|all] [--ball pingpong]
//
// rebound: first-bounce ratio (apex / 1 m drop, no drag) over Young's modulus, Poisson's
//          ratio and damping, for every ball preset's size and mass; no artificial force.
// steps:   which step sizes (Courant factor of the elastic wave's crossing time of the
//          smallest element) stay stable, explicit and implicit.
// smooth:  bounces 1-5 for a 1e-4 relative change of each parameter, and their spread over
//          16 drops whose release height moves by 1e-5 m; the classic ball's in the same run.
// cost:    CPU seconds per simulated second (this thread's CPU clock, one core) at ~100,
//          ~200 and ~400 nodes, against the classic ball on the default mesh.
// transfer: E and damping fitted to a 1.0 m drop of synth's physics, predicting 1.6 m,
//          beside the classic ball's stored set (fitted to the same 1.0 m heights).
// Every run is single-threaded and short (a drop of 1 m, at most 3 s simulated).
#include <fmt/format.h>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <nlopt.hpp>

#include "model/ball_preset.h"
#include "model/coefficient_table.h"
#include "bench/trial/fem_ball_model.h"
#include "model/point_mass_drop.h"
#include "model/soft_ball_model.h"

namespace {

using namespace bouncefit;

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Run {
  SimulationResult result;
  double cpu_s = 0;
};

Run Timed(const BallModel& model, const CoefficientValues& v, const SimulationOptions& o) {
  Run r;
  const double c0 = ThreadCpuSeconds();
  r.result = model.Simulate(v, o);
  r.cpu_s = ThreadCpuSeconds() - c0;
  return r;
}

std::string Heights(const SimulationResult& r, size_t n = 5) {
  if (!r.ok) return "FAILED: " + r.failure;
  std::string s;
  for (size_t i = 0; i < std::min(n, r.bounce_heights_m.size()); ++i)
    s += fmt::format("{}{:.4f}", s.empty() ? "" : " ", r.bounce_heights_m[i]);
  return s.empty() ? "(no bounce)" : s + " m";
}

// The pingpong FEM set the smoothness and cost sections start from.
const CoefficientValues kFemBase{{"youngs_modulus", 1e4}, {"poisson_ratio", 0.3}, {"damping", 1e-4}};

void Rebound() {
  std::printf("\n## rebound: first-bounce ratio (apex / drop), 1 m drop, no drag, no artificial force\n");
  std::printf("| ball | E (Pa) | nu | damping (s) | step (s) | ratio | CPU s |\n|---|---|---|---|---|---|---|\n");
  SimulationOptions o;
  o.drop_height_m = 1.0;
  o.duration_s = 1.05;  // the first apex and six frames after it
  for (const char* name : {"pingpong", "wiffle", "softball", "airball"}) {
    const FemBallModel m(*FindBallPreset(name));
    double lo = 1e9, hi = -1;
    for (double E : {3e3, 3e4, 1e5})
      for (double nu : {0.3, 0.45})
        for (double d : {0.0, 3e-4, 1e-3}) {
          const CoefficientValues v{{"youngs_modulus", E}, {"poisson_ratio", nu}, {"damping", d}, {"drag", 0}};
          const Run r = Timed(m, v, o);
          const double ratio = r.result.ok && !r.result.bounce_heights_m.empty()
                                   ? r.result.bounce_heights_m[0] / o.drop_height_m : -1;
          if (ratio >= 0) lo = std::min(lo, ratio), hi = std::max(hi, ratio);
          std::printf("| %s | %.0e | %.2f | %.0e | %.2e | %s | %.2f |\n", name, E, nu, d, m.TimeStep(v),
                      ratio >= 0 ? fmt::format("{:f}", ratio).substr(0, 5).c_str()
                                 : (r.result.ok ? "no bounce" : r.result.failure.c_str()),
                      r.cpu_s);
          std::fflush(stdout);
        }
    std::printf("| **%s range** | | | | | **%.3f - %.3f** | |\n", name, lo, hi);
  }
}

void Steps() {
  std::printf("\n## steps: stability over the step (Courant factor x the elastic wave's crossing time "
              "of the smallest element), pingpong, E 1e4 Pa, nu 0.3, damping 1e-4 s, no drag\n");
  std::printf("| solver | courant | step (s) | bounces 1-3 | CPU s per sim s |\n|---|---|---|---|---|\n");
  SimulationOptions o;
  o.drop_height_m = 1.0;
  o.duration_s = 2.0;
  CoefficientValues v = kFemBase;
  v["drag"] = 0;
  for (bool implicit : {false, true})
    for (double courant : {0.5, 1.0, 1.5, 2.0, 4.0}) {
      if (!implicit && courant > 2) continue;
      FemBallModelConfig cfg;
      cfg.courant = courant;
      cfg.implicit = implicit;
      const FemBallModel m(*FindBallPreset("pingpong"), cfg);
      const Run r = Timed(m, v, o);
      const double simulated = r.result.ok ? o.duration_s : 1;
      std::printf("| %s | %.1f | %.2e | %s | %.2f |\n", implicit ? "implicit" : "explicit", courant,
                  m.TimeStep(v), Heights(r.result, 3).c_str(), r.cpu_s / simulated);
      std::fflush(stdout);
    }
}

// Largest relative change (%) of bounces 1-5 between two runs, per bounce.
std::string Change(const SimulationResult& base, const SimulationResult& r) {
  if (!base.ok || !r.ok) return "FAILED: " + (base.ok ? r.failure : base.failure);
  std::string s;
  for (size_t i = 0; i < 5; ++i) {
    if (i >= base.bounce_heights_m.size() || i >= r.bounce_heights_m.size()) {
      s += " -";
      continue;
    }
    s += fmt::format(" {:+.3f}%", 100 * (r.bounce_heights_m[i] / base.bounce_heights_m[i] - 1));
  }
  return s;
}

void Spread(const BallModel& m, const CoefficientValues& v, const SimulationOptions& o0, const char* label) {
  std::vector<std::vector<double>> h(5);
  int failed = 0;
  double cpu = 0;
  for (int k = 0; k < 16; ++k) {
    SimulationOptions o = o0;
    o.drop_height_m += 1e-5 * (k - 7.5) / 7.5;
    const Run r = Timed(m, v, o);
    cpu += r.cpu_s;
    if (!r.result.ok) { ++failed; continue; }
    for (size_t i = 0; i < 5 && i < r.result.bounce_heights_m.size(); ++i) h[i].push_back(r.result.bounce_heights_m[i]);
  }
  std::printf("| %s | 16 drops, release +-1e-5 m |", label);
  for (auto& b : h) {
    if (b.size() < 2) { std::printf(" - |"); continue; }
    const auto [lo, hi] = std::minmax_element(b.begin(), b.end());
    double mean = 0;
    for (double x : b) mean += x / double(b.size());
    std::printf(" %.3f%% |", 100 * (*hi - *lo) / mean);
  }
  std::printf(" %d failed, %.1f s CPU |\n", failed, cpu);
  std::fflush(stdout);
}

void Smooth(const std::string& ball) {
  std::printf("\n## smooth: bounces 1-5 for a 1e-4 relative change of each parameter, and their spread "
              "(max - min over mean) over 16 drops with the release perturbed by up to 1e-5 m; %s, 1 m\n",
              ball.c_str());
  SimulationOptions o;
  o.drop_height_m = 1.0;
  o.duration_s = 3.0;
  o.min_bounce_height_m = 0.01;
  const BallPreset p = *FindBallPreset(ball);
  const FemBallModel fem(p);
  const Run base = Timed(fem, kFemBase, o);
  std::printf("fem base %s: %s (%.1f s CPU)\n", "E 1e4 Pa, nu 0.3, damping 1e-4 s", Heights(base.result).c_str(), base.cpu_s);
  std::printf("| model | change | bounce 1 | 2 | 3 | 4 | 5 |\n|---|---|---|---|---|---|---|\n");
  for (const char* name : {"youngs_modulus", "poisson_ratio", "damping", "drag"}) {
    CoefficientValues v = kFemBase;
    std::string err;
    const double x = fem.Complete(kFemBase, &err).at(name);
    v[name] = x * (1 + 1e-4);
    const Run r = Timed(fem, v, o);
    std::string cells = Change(base.result, r.result);
    for (auto& c : cells) if (c == ' ') c = '|';
    std::printf("| bullet-fem | %s x (1 + 1e-4) %s |\n", name, cells.c_str());
  }
  // The classic ball from its stored coefficients, measured the same way.
  const SoftBallModel classic(p);
  const CoefficientValues cv = SoftBallPresetTable(ball)->values;
  const Run cbase = Timed(classic, cv, o);
  std::printf("classic base (stored set): %s (%.1f s CPU)\n", Heights(cbase.result).c_str(), cbase.cpu_s);
  for (const char* name : {"linear_stiffness", "contact_hardness", "volume_conservation"}) {
    CoefficientValues v = cv;
    std::string err;
    v[name] = classic.Complete(cv, &err).at(name) * (1 + 1e-4);
    const Run r = Timed(classic, v, o);
    std::string cells = Change(cbase.result, r.result);
    for (auto& c : cells) if (c == ' ') c = '|';
    std::printf("| bullet-softbody | %s x (1 + 1e-4) %s |\n", name, cells.c_str());
  }
  std::printf("| model | spread | bounce 1 | 2 | 3 | 4 | 5 | |\n|---|---|---|---|---|---|---|---|\n");
  Spread(fem, kFemBase, o, "bullet-fem");
  Spread(classic, cv, o, "bullet-softbody");
}

void Cost() {
  std::printf("\n## cost: CPU s per simulated s (one core, thread CPU clock), pingpong, 1 m drop, "
              "0.6 s simulated (fall and impact) without early stop\n");
  SimulationOptions o;
  o.drop_height_m = 1.0;
  o.duration_s = 0.6;
  o.min_bounce_height_m = -1;
  const BallPreset p = *FindBallPreset("pingpong");
  const SoftBallModel classic(p);
  const Run base = Timed(classic, SoftBallPresetTable("pingpong")->values, o);
  std::printf("baseline bullet-softbody (stored set, 93 nodes, dt 1/480 s): %.4f CPU s per sim s (%.0fx real time)\n",
              base.cpu_s / o.duration_s, o.duration_s / base.cpu_s);
  std::printf("| E (Pa) | mesh_resolution | nodes | tetrahedra | step (s) | CPU s per sim s | real time x | / classic |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  const FemBallModel fem(p);
  for (double E : {1e4, 1e5})
    for (int res : {3, 4, 6}) {
      CoefficientValues v = kFemBase;
      v["youngs_modulus"] = E;
      v["mesh_resolution"] = res;
      const auto mesh = fem.Mesh(v);
      SimulationOptions traced = o;
      traced.record_trajectory = true;  // to know how far a run cut by the wall-time cap got
      const Run r = Timed(fem, v, traced);
      const double simulated = r.result.trajectory.empty() ? o.duration_s : r.result.trajectory.back().t_s;
      const double rate = r.cpu_s / simulated;
      std::printf("| %.0e | %d | %zu | %zu | %.2e | %.3f | %.2f | %.0f |%s\n", E, res, mesh->nodes.size(),
                  mesh->tetras.size(), fem.TimeStep(v), rate, 1 / rate, rate / (base.cpu_s / o.duration_s),
                  r.result.ok ? "" : (" (" + fmt::format("{:f}", simulated).substr(0, 5) + " s simulated: " +
                                      r.result.failure + ")").c_str());
      std::fflush(stdout);
    }
  // The criterion: a whole 1 m ping-pong drop (until bounces fall below 1 cm).
  SimulationOptions whole;
  whole.drop_height_m = 1.0;
  whole.duration_s = 6.0;
  whole.record_trajectory = true;
  const Run r = Timed(fem, kFemBase, whole);
  const double simulated = r.result.trajectory.empty() ? 0 : r.result.trajectory.back().t_s;
  std::printf("whole 1 m drop (E 1e4 Pa, 93 nodes): %.2f s simulated in %.2f s CPU: %.2fx real time "
              "(criterion: 10x)\n", simulated, r.cpu_s, simulated / r.cpu_s);
  // The cheapest setting that still bounces like a ping-pong ball: the longest step whose
  // heights do not depend on it (courant 1, section steps), no damping (no damping solve).
  FemBallModelConfig fast_cfg;
  fast_cfg.courant = 1.0;
  const FemBallModel fast(p, fast_cfg);
  CoefficientValues fast_v = kFemBase;
  fast_v["youngs_modulus"] = 2e4;
  fast_v["damping"] = 0;
  const Run f = Timed(fast, fast_v, whole);
  const double fast_simulated = f.result.trajectory.empty() ? 0 : f.result.trajectory.back().t_s;
  std::printf("best case (E 2e4 Pa, no damping, courant 1, 93 nodes): %s; %.2f s simulated in %.2f s "
              "CPU: %.2fx real time\n", Heights(f.result).c_str(), fast_simulated, f.cpu_s,
              fast_simulated / f.cpu_s);
}

// Squared relative errors of the first n heights (a missing bounce counts as a full miss).
double Misfit(const SimulationResult& r, const std::vector<double>& truth, size_t n) {
  if (!r.ok) return 1e3;
  double e = 0;
  for (size_t i = 0; i < n && i < truth.size(); ++i) {
    const double h = i < r.bounce_heights_m.size() ? r.bounce_heights_m[i] : 0;
    e += (h / truth[i] - 1) * (h / truth[i] - 1);
  }
  return e;
}

std::vector<double> TruthHeights(const BallPreset& p, double drop) {
  PointMassDropConfig c;
  c.ball = p;
  c.drop_height_m = drop;
  const PointMassDropResult r = SimulatePointMassDrop(c);
  std::vector<double> h;
  for (size_t i = 1; i < r.apex_heights_m.size() && h.size() < 5; ++i)
    if (r.apex_heights_m[i] >= 0.02) h.push_back(r.apex_heights_m[i]);
  return h;
}

std::string Errors(const SimulationResult& r, const std::vector<double>& truth) {
  if (!r.ok) return "FAILED: " + r.failure;
  std::string s;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (i >= r.bounce_heights_m.size()) { s += " missing"; continue; }
    s += fmt::format(" {:+.1f}%", 100 * (r.bounce_heights_m[i] / truth[i] - 1));
  }
  return s;
}

// Fit E and damping (nu 0.3, Cd the preset's; a 20-point grid, then BOBYQA) to the first
// three heights of a 1.0 m drop
// of synth's physics (model/point_mass_drop, the preset's e(v)), then predict 1.6 m; the
// classic ball's stored set (fitted the same way by soft_ball_preset_search_bench) beside it.
void Transfer(const std::string& ball, int max_evals) {
  std::printf("\n## transfer: fit to a 1.0 m drop (first 3 heights, synth physics), predict 1.6 m; %s\n",
              ball.c_str());
  const BallPreset p = *FindBallPreset(ball);
  const std::vector<double> truth1 = TruthHeights(p, 1.0), truth16 = TruthHeights(p, 1.6);
  const FemBallModel fem(p);
  SimulationOptions o1;
  o1.drop_height_m = 1.0;
  o1.duration_s = 3.0;
  SimulationOptions o16 = o1;
  o16.drop_height_m = 1.6;
  o16.duration_s = 4.0;
  auto values = [](const std::vector<double>& x) {
    return CoefficientValues{{"youngs_modulus", std::pow(10.0, x[0])}, {"poisson_ratio", 0.3},
                             {"damping", 1e-4 * x[1]}};
  };
  int evals = 0;
  double cpu = 0;
  nlopt::opt opt(nlopt::LN_BOBYQA, 2);
  opt.set_lower_bounds({3.5, 0.0});
  opt.set_upper_bounds({5.0, 30.0});
  opt.set_maxeval(max_evals);
  opt.set_initial_step({0.1, 1.0});
  opt.set_xtol_rel(1e-4);
  std::function<double(const std::vector<double>&)> objective = [&](const std::vector<double>& x) {
    const Run r = Timed(fem, values(x), o1);
    cpu += r.cpu_s;
    ++evals;
    return Misfit(r.result, truth1, 3);
  };
  opt.set_min_objective(
      [](const std::vector<double>& x, std::vector<double>&, void* f) {
        return (*static_cast<std::function<double(const std::vector<double>&)>*>(f))(x);
      },
      &objective);
  // A coarse grid first (the objective has failed and bounce-less regions a local search
  // cannot see past), then BOBYQA from its best point.
  std::vector<double> x{4.3, 1.0};
  double best = 1e300;
  for (double logE : {3.5, 3.875, 4.25, 4.625, 5.0})
    for (double d : {0.0, 3.0, 10.0, 30.0}) {
      const double f = objective({logE, d});
      if (f < best) best = f, x = {logE, d};
    }
  try {
    opt.optimize(x, best);
  } catch (const std::exception& e) {
    std::printf("(search stopped: %s)\n", e.what());
  }
  std::printf("bullet-fem fit: E %.4g Pa, damping %.3g s, misfit %.2e, %d simulations, %.0f s CPU\n",
              std::pow(10.0, x[0]), 1e-4 * x[1], best, evals, cpu);
  std::printf("| model | drop | errors vs truth, bounces 1-%zu |\n|---|---|---|\n", truth16.size());
  std::printf("| bullet-fem | 1.0 m (fitted) |%s |\n", Errors(fem.Simulate(values(x), o1), truth1).c_str());
  std::printf("| bullet-fem | 1.6 m (predicted) |%s |\n", Errors(fem.Simulate(values(x), o16), truth16).c_str());
  const SoftBallModel classic(p);
  const CoefficientValues cv = SoftBallPresetTable(ball)->values;
  std::printf("| bullet-softbody (stored set) | 1.0 m (fitted) |%s |\n", Errors(classic.Simulate(cv, o1), truth1).c_str());
  std::printf("| bullet-softbody (stored set) | 1.6 m (predicted) |%s |\n", Errors(classic.Simulate(cv, o16), truth16).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  std::string section = "all", ball = "pingpong";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::printf("usage: %s [--section rebound|steps|smooth|cost|transfer|all] [--ball NAME (smooth, transfer)]\n"
                  "Measures the Bullet FEM ball against the classic soft ball.\n", argv[0]);
      return 0;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "fem_ball_bench: error: %s needs a value (see --help)\n", a.c_str());
      return 2;
    }
    if (a == "--section") section = argv[++i];
    else if (a == "--ball") ball = argv[++i];
    else {
      std::fprintf(stderr, "fem_ball_bench: error: unknown flag %s (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (!FindBallPreset(ball)) {
    std::fprintf(stderr, "fem_ball_bench: error: unknown ball '%s' (known: %s)\n", ball.c_str(),
                 BallPresetNames().c_str());
    return 2;
  }
  const bool all = section == "all";
  if (!all && section != "rebound" && section != "steps" && section != "smooth" && section != "cost" &&
      section != "transfer") {
    std::fprintf(stderr, "fem_ball_bench: error: unknown section '%s' (see --help)\n", section.c_str());
    return 2;
  }
  if (all || section == "cost") Cost();
  if (all || section == "rebound") Rebound();
  if (all || section == "steps") Steps();
  if (all || section == "smooth") Smooth(ball);
  if (all || section == "transfer") Transfer(ball, 25);
  return 0;
}
