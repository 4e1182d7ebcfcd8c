// Finds, for each ball preset, soft-body coefficients whose first three simulated bounce
// heights match the preset's point-mass heights (the `synth` physics), and writes them to
// model/presets/soft_ball_<preset>.json. The tests re-simulate those files and check them to
// 2%; this tool is how they were found (docs/MODEL.md).
//
//   build/bench/soft_ball_preset_search_bench [--ball NAME] [--drop 1.0] [--write DIR]
//       [--evals N] [--starts N] [--robust N] [--bounces N]
//       [--fix name=value,...] [--range name=lo:hi] [--start name=value,...]
//
// Search: NLopt's bounded Subplex on the coefficients below (plus --range ones; --fix ones
// and all others keep a value; drag is the preset's Cd unless searched), from a few starting
// points, minimising the sum of squared relative errors of the first --bounces heights.
// The heights are chaotic in the coefficients (docs/MODEL.md), so with --robust N a point
// scores its worst over N ppm-perturbed copies. Deterministic (fixed starts, serial).
// --evals 0 evaluates (and writes) the --start point only.
#include <nlopt.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/ball_preset.h"
#include "model/point_mass_drop.h"
#include "model/soft_ball_model.h"
#include "bench/paired_options.h"

namespace {

using namespace bouncefit;

struct Searched {
  std::string name;
  double lower, upper;
};

// The coefficients searched, with the sub-range searched (inside the model's bounds).
std::vector<Searched> kSearched = {
    {"linear_stiffness", 0.02, 1.0}, {"pressure", 0.0, 1.0},       {"volume_conservation", 0.0, 100.0},
    {"contact_hardness", 0.0, 1.0},  {"rebound_boost", 0.0, 1.0},
};
CoefficientValues g_fixed;
CoefficientValues g_start;  // first starting point (--start), else spread over the box

std::vector<double> TargetHeights(const BallPreset& ball, double drop, int n) {
  PointMassDropConfig c;
  c.ball = ball;
  c.drop_height_m = drop;
  c.end_time_s = 30;
  const PointMassDropResult r = SimulatePointMassDrop(c);
  std::vector<double> h;
  for (size_t i = 1; i < r.apex_heights_m.size() && int(h.size()) < n; ++i) h.push_back(r.apex_heights_m[i]);
  return h;
}

struct Problem {
  const SoftBallModel* model;
  std::vector<double> target;
  SimulationOptions options;
  int robust = 1;  // evaluations per point: linear_stiffness x (1 + k ppm), k = 0..robust-1
  int evals = 0;
  double best = 1e300;
  std::vector<double> best_x;
};

CoefficientValues ToValues(const std::vector<double>& x) {
  CoefficientValues v = g_fixed;
  for (size_t i = 0; i < kSearched.size(); ++i) v[kSearched[i].name] = x[i];
  return v;
}

double Objective(const std::vector<double>& x, std::vector<double>& /*grad*/, void* data) {
  auto* p = static_cast<Problem*>(data);
  ++p->evals;
  // The heights are chaotic in the coefficients (docs/MODEL.md): with robust > 1 the point
  // is scored by its worst error over a few ppm-perturbed copies, which steers the search
  // to calm regions and away from lucky draws.
  double f = 0;
  for (int k = 0; k < p->robust; ++k) {
    CoefficientValues v = ToValues(x);
    if (k > 0) {
      std::string err;
      v = p->model->Complete(v, &err);
      v["linear_stiffness"] *= 1 - 1e-6 * k;  // stays inside [0, 1]
    }
    const SimulationResult r = p->model->Simulate(v, p->options);
    double fk = 0;
    for (size_t i = 0; i < p->target.size(); ++i) {
      const double s = i < r.bounce_heights_m.size() ? r.bounce_heights_m[i] : 0;
      const double e = (s - p->target[i]) / p->target[i];
      fk += e * e;
    }
    if (!r.ok) fk += 10;
    f = std::max(f, fk);
  }
  if (f < p->best) {
    p->best = f;
    p->best_x = x;
  }
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> balls = {"pingpong", "wiffle", "softball", "airball"};
  double drop = 1.0;
  int evals = 400, starts = 4, robust = 3, bounces = 3;
  std::string write_dir;
  const char* usage =
      "usage: %s [--ball NAME] [--drop M] [--evals N (0: evaluate --start only)] "
      "[--starts N] [--robust N] [--bounces N] [--fix k=v,...] [--range k=lo:hi] "
      "[--start k=v,...] [--write DIR]\n";
  for (int i = 1; i < argc; i += 2) {
    if (const auto end = bouncefit::bench::HelpOrMissingValue(argc, argv, i, usage)) return *end;
    if (!std::strcmp(argv[i], "--ball")) balls = {argv[i + 1]};
    else if (!std::strcmp(argv[i], "--drop")) drop = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--evals")) evals = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--starts")) starts = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--robust")) robust = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--bounces")) bounces = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--write")) write_dir = argv[i + 1];
    else if (!std::strcmp(argv[i], "--fix")) {  // name=value: not searched
      for (const auto& [k, v] : ParseCoefficientList(argv[i + 1])) {
        g_fixed[k] = v;
        std::erase_if(kSearched, [&](const Searched& s) { return s.name == k; });
      }
    } else if (!std::strcmp(argv[i], "--start")) {
      g_start = ParseCoefficientList(argv[i + 1]);
    } else if (!std::strcmp(argv[i], "--range")) {  // name=lo:hi, searched
      const std::string a = argv[i + 1];
      const auto eq = a.find('='), colon = a.find(':');
      const std::string k = a.substr(0, eq);
      std::erase_if(kSearched, [&](const Searched& s) { return s.name == k; });
      kSearched.push_back({k, std::atof(a.substr(eq + 1, colon - eq - 1).c_str()), std::atof(a.substr(colon + 1).c_str())});
    }
    else {
      return bouncefit::bench::PrintUsage(usage, argv[0], false);
    }
  }
  for (const std::string& name : balls) {
    const auto preset = FindBallPreset(name);
    if (!preset) {
      std::fprintf(stderr, "unknown ball %s\n", name.c_str());
      return 2;
    }
    const SoftBallModel model(*preset);
    bool fixed_drag = g_fixed.count("drag") > 0, searched_drag = false;
    for (const auto& sd : kSearched) searched_drag |= sd.name == "drag";
    if (!fixed_drag && !searched_drag) g_fixed["drag"] = preset->drag_coefficient;
    Problem p;
    p.model = &model;
    p.robust = robust;
    p.target = TargetHeights(*preset, drop, bounces);
    p.options.drop_height_m = drop;
    p.options.min_bounce_height_m = 0.5 * p.target.back();
    p.options.duration_s = 8;
    std::printf("%s: target heights", name.c_str());
    for (double h : p.target) std::printf(" %.5f", h);
    std::printf(" m\n");

    const auto t0 = std::chrono::steady_clock::now();
    const size_t n = kSearched.size();
    std::vector<double> lo(n), hi(n);
    for (size_t i = 0; i < n; ++i) {
      lo[i] = kSearched[i].lower;
      hi[i] = kSearched[i].upper;
    }
    if (evals == 0) {  // no search: evaluate (and write) the --start point
      p.best_x.assign(n, 0);
      for (size_t i = 0; i < n; ++i)
        p.best_x[i] = g_start.count(kSearched[i].name) ? g_start.at(kSearched[i].name) : lo[i];
      for (const auto& [k, v] : g_start)
        if (std::none_of(kSearched.begin(), kSearched.end(), [&](const Searched& sd) { return sd.name == k; }))
          g_fixed[k] = v;
    }
    for (int s = 0; s < (evals == 0 ? 0 : starts); ++s) {
      // Starting points spread over the box (fixed: the search is reproducible).
      std::vector<double> x(n);
      for (size_t i = 0; i < n; ++i) {
        const double frac = std::fmod(0.2 + 0.618034 * double(s + 1) * double(i + 1), 1.0);
        x[i] = lo[i] + (hi[i] - lo[i]) * (0.1 + 0.8 * frac);
      }
      if (s == 0)
        for (size_t i = 0; i < n; ++i)
          if (g_start.count(kSearched[i].name)) x[i] = std::clamp(g_start.at(kSearched[i].name), lo[i], hi[i]);
      if (s > 0 && s % 2 == 0 && !p.best_x.empty()) x = p.best_x;  // restart from the best
      nlopt::opt opt(nlopt::LN_SBPLX, unsigned(n));
      opt.set_lower_bounds(lo);
      opt.set_upper_bounds(hi);
      opt.set_min_objective(Objective, &p);
      opt.set_maxeval(evals);
      opt.set_stopval(1e-6);
      std::vector<double> step(n);
      for (size_t i = 0; i < n; ++i) step[i] = 0.15 * (hi[i] - lo[i]);
      opt.set_initial_step(step);
      double f = 0;
      try {
        opt.optimize(x, f);
      } catch (const std::exception& e) {
        std::printf("  start %d: %s\n", s, e.what());
      }
      std::printf("  start %d: best so far %.3g after %d simulations\n", s, p.best, p.evals);
      if (p.best < 1e-6) break;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const CoefficientValues best = ToValues(p.best_x);
    const SimulationResult r = model.Simulate(best, p.options);
    std::printf("  %d simulations, %.1f s; simulated", p.evals, seconds);
    double worst = 0;
    for (size_t i = 0; i < p.target.size() && i < r.bounce_heights_m.size(); ++i) {
      std::printf(" %.5f", r.bounce_heights_m[i]);
      worst = std::max(worst, std::abs(r.bounce_heights_m[i] / p.target[i] - 1));
    }
    // The chaos floor at the result: worst error over ppm-perturbed copies.
    double worst_perturbed = worst;
    for (int k = 1; k <= 8; ++k) {
      std::string err;
      CoefficientValues v = model.Complete(best, &err);
      v["linear_stiffness"] *= 1 - 1e-6 * k;
      const SimulationResult rk = model.Simulate(v, p.options);
      for (size_t i = 0; i < p.target.size(); ++i)
        worst_perturbed = std::max(worst_perturbed, i < rk.bounce_heights_m.size() ? std::abs(rk.bounce_heights_m[i] / p.target[i] - 1) : 1.0);
    }
    std::printf(" m, worst error %.2f%% (%.2f%% over 1-8 ppm changes of linear_stiffness)\n  coefficients:", 100 * worst, 100 * worst_perturbed);
    for (const auto& [k, v] : best) std::printf(" %s=%.6g", k.c_str(), v);
    std::printf("\n");

    if (!write_dir.empty()) {
      std::string err;
      const CoefficientValues all = model.Complete(best, &err);
      nlohmann::ordered_json j;
      j["model"] = model.name();
      j["ball"] = name;
      j["time_step_s"] = model.config().time_step_s;
      j["position_iterations"] = model.config().position_iterations;
      j["drop_height_m"] = drop;
      j["target_heights_m"] = p.target;
      j["simulated_heights_m"] = r.bounce_heights_m;
      j["worst_error"] = worst;
      j["worst_error_ppm_perturbed"] = worst_perturbed;
      j["found_by"] = "build/bench/soft_ball_preset_search_bench --ball " + name + " --robust " +
                      std::to_string(robust) + " --bounces " + std::to_string(bounces);
      nlohmann::ordered_json coeffs;
      for (const auto& s : model.Coefficients()) coeffs[s.name] = all.at(s.name);
      j["coefficients"] = coeffs;
      const std::string path = write_dir + "/soft_ball_" + name + ".json";
      std::ofstream(path) << j.dump(2) << "\n";
      if (!fixed_drag) g_fixed.erase("drag");
      std::printf("  wrote %s\n", path.c_str());
    }
  }
  return 0;
}
