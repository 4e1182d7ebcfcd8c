// fit_bench: the two searches side by side on the same inputs, and the per-bounce latency
// of the live fit.
//
//   fit_bench [--model bullet-softbody|point-mass] [--balls pingpong,wiffle,softball,airball]
//             [--drop 1.0] [--bounces 6] [--budget 300] [--threads 0] [--from-preset]
//             [--neighbours N]
//   fit_bench --realtime [--ball pingpong] [--drop 1.0] [--detector-delay 0.05]
//   fit_bench --law [--balls ...] [--inputs 0.8,0.9,1.0,1.2,1.4] [--budget 300]
//             [--step F] [--range-scale S] [--stage2 N]   (the default's variants)
//
// Searches: recorded heights come from model/point_mass_drop with the ball's preset (synth's
// physics); both searches start from the same point (the model's defaults, or the preset
// table when the model has one), fit the same coefficients, and get the same budget. For
// each: simulations, RMS residual, wall time; and the number of simulations the default
// search needed to reach the paper search's final residual (the ratio is the figure).
//
// --neighbours N: the chaos floor at each search's answer: N points a 1e-4 (fraction of each
// range) Gaussian step away, simulated; prints how many of them reach the paper search's
// final residual, and their median residual. The soft body's heights are chaotic in the
// coefficients (docs/MODEL.md), so a final residual is one draw from such a spread.
//
// --law: the comparison of searches on the default objective (the restitution law,
// heights and flight times, one free drop): for each ball, five inputs (drops of synth's
// point mass from --inputs heights); the paper's serial search on rebound_restitution, its
// slope and drag (full bounds, the session's start, --budget soft-body runs) against the
// default search (fit/restitution_fit.h: the point mass, then Levenberg-Marquardt on the soft
// ball near it). The figure: soft-body simulations the default needed to reach the paper
// search's final objective, over the paper search's simulations; median per ball (the
// target: <= 1/3). Point-mass runs (microseconds) are counted apart.
//
// Realtime: the peaks of a drop are replayed on the wall clock (each emitted
// --detector-delay after its apex) into the live fit worker; prints, per bounce, the time
// from apex to its update and whether it was out before the next apex.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fit/fit_models.h"
#include "fit/fit_session.h"
#include "fit/fit_worker.h"
#include "fit/nlopt_search.h"
#include "fit/paper_search.h"
#include "fit/restitution_fit.h"
#include "model/ball_preset.h"
#include "model/model_by_name.h"
#include "model/point_mass_drop.h"
#include "model/point_mass_model.h"

using namespace bouncefit;

namespace {

struct Args {
  std::string model = "bullet-softbody";
  std::vector<std::string> balls = {"pingpong", "wiffle", "softball", "airball"};
  double drop = 1.0;
  int bounces = 6;
  int budget = 300;
  int threads = 0;
  bool realtime = false;
  bool law = false;
  double range_scale = 0;  // --law: scales the default's stage-2 ranges (0: as the session)
  int stage2 = 0;          // --law: the default's stage-2 budget (0: as the session)
  std::vector<double> inputs = {0.8, 0.9, 1.0, 1.2, 1.4};
  double detector_delay = 0.05;
  int per_bounce = 16;
  double step = 0;  // NLopt initial step override (0: the search's default)
  bool from_preset = false;  // start from the preset table instead of the model defaults
  int neighbours = 0;        // chaos-floor samples around each answer (0: none)
};

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  return out;
}

Args Parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "fit_bench: %s needs a value\n", k.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (k == "--model") a.model = next();
    else if (k == "--balls" || k == "--ball") a.balls = Split(next());
    else if (k == "--drop") a.drop = std::stod(next());
    else if (k == "--bounces") a.bounces = std::stoi(next());
    else if (k == "--budget") a.budget = std::stoi(next());
    else if (k == "--threads") a.threads = std::stoi(next());
    else if (k == "--realtime") a.realtime = true;
    else if (k == "--law") a.law = true;
    else if (k == "--range-scale") a.range_scale = std::stod(next());
    else if (k == "--stage2") a.stage2 = std::stoi(next());
    else if (k == "--inputs") {
      a.inputs.clear();
      for (const auto& h : Split(next())) a.inputs.push_back(std::stod(h));
    }
    else if (k == "--detector-delay") a.detector_delay = std::stod(next());
    else if (k == "--per-bounce") a.per_bounce = std::stoi(next());
    else if (k == "--from-preset") a.from_preset = true;
    else if (k == "--neighbours") a.neighbours = std::stoi(next());
    else if (k == "--step") a.step = std::stod(next());
    else if (k == "--help" || k == "-h") {
      std::printf(
          "usage: fit_bench [--model NAME] [--balls A,B,...] [--drop M] [--bounces N] [--budget N]\n"
          "                 [--threads N] [--realtime] [--law] [--range-scale X] [--stage2 N]\n"
          "                 [--inputs H1,H2,... (m)] [--detector-delay S] [--per-bounce N]\n"
          "                 [--from-preset] [--neighbours N] [--step X]\n"
          "Fits the ball model to rendered drops and prints its cost and residuals (docs/PERFORMANCE.md).\n");
      std::exit(0);
    } else {
      std::fprintf(stderr, "fit_bench: unknown argument %s\n", k.c_str());
      std::exit(2);
    }
  }
  return a;
}

PointMassDropResult Truth(const BallPreset& ball, double drop) {
  PointMassDropConfig c;
  c.ball = ball;
  c.drop_height_m = drop;
  c.end_time_s = 20;
  return SimulatePointMassDrop(c);
}

int Searches(const Args& a) {
  std::printf("fit_bench: searches on %s, drop %.2f m, up to %d bounces >= 1 cm, budget %d "
              "simulations each, from %s\n\n",
              a.model.c_str(), a.drop, a.bounces, a.budget,
              a.from_preset ? "the preset tables" : "the model defaults");
  std::printf("%-9s | %-6s %6s %10s %8s | %-6s %6s %10s %8s %8s | %s\n", "ball", "paper",
              "sims", "rms (mm)", "wall s", "nlopt", "sims", "rms (mm)", "wall s", "reach@",
              "paper/reach");
  int failures = 0;
  for (const auto& name : a.balls) {
    const BallPreset ball = ResolveBallPreset(name);
    const auto truth = Truth(ball, a.drop);
    std::vector<double> r;
    for (size_t i = 1; i < truth.apex_heights_m.size() && static_cast<int>(r.size()) < a.bounces; ++i) {
      if (truth.apex_heights_m[i] < 0.01) break;
      r.push_back(truth.apex_heights_m[i]);
    }
    auto model = MakeBallModel(a.model, ball);
    FitSessionConfig cfg;
    ConfigureSessionForModel(*model, ball, &cfg);
    // From scratch (model defaults) unless asked: near a preset table both searches have
    // little to do.
    if (!a.from_preset) cfg.start.clear();
    // The session's own problem (free coefficients, grid, duration), via a session.
    FitSession session(*model, nullptr, cfg);
    session.AddPeak({0, 0, a.drop, 0, 0});
    for (size_t i = 0; i < r.size(); ++i) session.AddPeak({0, static_cast<int>(i + 1), r[i], 0, 0});
    FitProblem p;
    p.model = model.get();
    for (const auto& s : model->Coefficients()) {
      bool never = s.name == "radius" || !(s.upper > s.lower);
      for (const auto& pat : cfg.never_fit) never = never || s.name.find(pat) != std::string::npos;
      if (!never) p.free.push_back(s);
    }
    p.fixed = session.warm_start();
    p.recorded_m = r;
    p.grid = cfg.grid;
    p.simulation.drop_height_m = a.drop;
    p.simulation.duration_s =
        cfg.duration_margin * FreeFallApexTime(a.drop, r, static_cast<int>(r.size())) + 0.2;
    p.simulation.min_bounce_height_m = 0.5 * std::min(0.01, r.back());
    SearchOptions o;
    o.max_evaluations = a.budget;
    o.threads = a.threads;
    const SearchResult paper = PaperSearch(p, session.warm_start(), o);
    NloptSearchOptions no;
    if (a.step > 0) no.initial_step = a.step;
    const SearchResult fast = NloptSearch(p, session.warm_start(), o, no);
    int reach = -1;
    for (size_t i = 0; i < fast.best_history.size(); ++i)
      if (fast.best_history[i] <= paper.objective * (1 + 1e-12)) {
        reach = static_cast<int>(i) + 1;
        break;
      }
    const std::string ratio = reach > 0 ? fmt::format("{:.1f}x", double(paper.evaluations) / reach) : "never";
    std::printf("%-9s | %-6s %6d %10.3f %8.1f | %-6s %6d %10.3f %8.1f %8d | %s\n", name.c_str(),
                "", paper.evaluations, paper.rms_m * 1000, paper.wall_time_s, "",
                fast.evaluations, fast.rms_m * 1000, fast.wall_time_s, reach, ratio.c_str());
    for (const auto* res : {&paper, &fast}) {
      std::printf("          %-6s:", res == &paper ? "paper" : "nlopt");
      for (const auto& spec : p.free) std::printf(" %s=%.4g", spec.name.c_str(), res->values.at(spec.name));
      std::printf("\n          heights:");
      for (size_t i = 0; i < r.size(); ++i)
        std::printf(" %.3f/%.3f", r[i], i < res->simulated_m.size() ? res->simulated_m[i] : 0.0);
      std::printf("\n");
    }
    if (a.neighbours > 0) {
      for (const auto* res : {&paper, &fast}) {
        SearchOptions no_budget = o;
        no_budget.max_evaluations = a.neighbours;
        FitObjective f(p, no_budget);
        std::mt19937 rng(7);
        std::normal_distribution<double> step(0.0, 1e-4);
        const auto centre = f.ToUnit(res->values);
        std::vector<std::vector<double>> xs(static_cast<size_t>(a.neighbours), centre);
        for (auto& x : xs)
          for (double& u : x) u += step(rng);
        std::vector<double> rms;
        for (const auto& e : f.EvaluateBatch(xs))
          rms.push_back(e.ok ? std::sqrt(e.objective / double(r.size())) : INFINITY);
        std::sort(rms.begin(), rms.end());
        const long beat = std::count_if(rms.begin(), rms.end(),
                                        [&](double v) { return v <= paper.rms_m; });
        std::printf("          %-6s: %d neighbours 1e-4 away: %ld reach the paper's %.3f mm; "
                    "median %.3f mm, best %.3f mm\n",
                    res == &paper ? "paper" : "nlopt", a.neighbours, beat, paper.rms_m * 1000,
                    rms[rms.size() / 2] * 1000, rms.front() * 1000);
      }
    }
    std::fflush(stdout);
    if (reach < 0 || 3 * reach > paper.evaluations) ++failures;
  }
  std::printf("\nreach@ = simulations the default (nlopt) search used to get at or below the "
              "paper search's final residual; must-show: paper/reach >= 3.\n");
  return failures == 0 ? 0 : 1;
}

int LawSearches(const Args& a) {
  std::printf("fit_bench --law: paper search vs the default (restitution law), budget %d "
              "soft-body simulations, inputs: drops from", a.budget);
  for (double h : a.inputs) std::printf(" %.2f", h);
  std::printf(" m\n\n| ball | drop m | paper sims | paper RMS mm | default soft sims (+ point-mass runs) | "
              "default RMS mm | default reached paper's at | ratio |\n|---|---|---|---|---|---|---|---|\n");
  bool all = true;
  std::vector<std::string> summary;
  for (const auto& name : a.balls) {
    const BallPreset ball = ResolveBallPreset(name);
    auto model = MakeBallModel("bullet-softbody", ball);
    PointMassModel point_mass(ball);
    FitSessionConfig cfg;  // the default: impact "restitution", its start
    ConfigureSessionForModel(*model, ball, &cfg);
    std::vector<double> ratios;
    for (double drop : a.inputs) {
      const auto truth = Truth(ball, drop);
      FitProblem p;
      p.model = model.get();
      p.fixed = cfg.start;
      for (size_t i = 1; i < truth.apex_heights_m.size() && truth.apex_heights_m[i] >= 0.01; ++i)
        p.recorded_m.push_back(truth.apex_heights_m[i]);
      p.recorded_flight_s = FlightTimes(truth.impact_times_s, p.recorded_m.size());
      p.flight_weight_mps = cfg.flight_weight_mps;
      p.simulation.drop_height_m = drop;
      p.simulation.duration_s =
          cfg.duration_margin * FreeFallApexTime(drop, p.recorded_m, static_cast<int>(p.recorded_m.size())) + 0.2;
      p.simulation.min_bounce_height_m = 0.005;
      for (const auto& s : model->Coefficients())
        if (s.name == "rebound_restitution" || s.name == "rebound_restitution_per_mps" || s.name == "drag")
          p.free.push_back(s);
      SearchOptions o;
      o.max_evaluations = a.budget;
      o.threads = a.threads;
      const SearchResult paper = PaperSearch(p, p.fixed, o);
      RestitutionFitOptions ro;  // the session's, unless --step says otherwise
      if (a.step > 0) ro.fd_step = a.step;
      if (a.range_scale > 0) {
        ro.restitution_range *= a.range_scale;
        ro.slope_range *= a.range_scale;
        ro.drag_factor = std::pow(ro.drag_factor, a.range_scale);
      }
      if (a.stage2 > 0) ro.max_evaluations = a.stage2;
      const RestitutionFit def = FitRestitutionCurve(p, point_mass, o, ro);
      int reach = -1;
      for (size_t i = 0; i < def.soft.best_history.size(); ++i)
        if (def.soft.best_history[i] <= paper.objective * (1 + 1e-12)) {
          reach = static_cast<int>(i) + 1;
          break;
        }
      // Not reached within its own budget: counted as the whole paper budget (ratio >= 1).
      const double ratio = (reach > 0 ? reach : a.budget) / static_cast<double>(std::max(1, paper.evaluations));
      ratios.push_back(ratio);
      std::printf("| %s | %.2f | %d | %.2f | %d (+%d) | %.2f | %s | %.3f |\n", name.c_str(), drop,
                  paper.evaluations, paper.rms_m * 1000, def.soft.evaluations,
                  def.point_mass.evaluations, def.soft.rms_m * 1000,
                  reach > 0 ? std::to_string(reach).c_str() : "never", ratio);
      std::fflush(stdout);
    }
    std::sort(ratios.begin(), ratios.end());
    const double median = ratios[ratios.size() / 2];
    all = all && median <= 1.0 / 3;
    summary.push_back(fmt::format("{}: median ratio {:.3f} over {} inputs ({} 1/3)", name, median, ratios.size(),
                                  median <= 1.0 / 3 ? "within" : "NOT within"));
  }
  std::printf("\n");
  for (const auto& line : summary) std::printf("%s\n", line.c_str());
  std::printf("default reaches the paper search's objective with <= 1/3 of its simulations on "
              "every ball: %s\n", all ? "yes" : "no");
  return 0;
}

int Realtime(const Args& a) {
  const BallPreset ball = ResolveBallPreset(a.balls.front());
  const auto truth = Truth(ball, a.drop);
  auto model = MakeBallModel(a.model, ball);
  PointMassModel quick(ball);
  FitSessionConfig cfg;
  cfg.threads = a.threads;
  cfg.max_evaluations_per_bounce = a.per_bounce;
  ConfigureSessionForModel(*model, ball, &cfg);

  using Clock = std::chrono::steady_clock;
  std::mutex m;
  std::map<int, double> update_at;  // bounce -> wall seconds since release (model update)
  std::map<int, int> evals;
  Clock::time_point t0;
  FitWorker worker(std::make_unique<FitSession>(*model, &quick, cfg), [&](const FitUpdate& u) {
    if (u.model == "point-mass" || u.final) return;
    std::lock_guard<std::mutex> lock(m);
    update_at[u.after_bounce] =
        std::chrono::duration<double>(Clock::now() - t0).count();
    evals[u.after_bounce] = u.evaluations;
  });
  worker.Start();
  const double release = truth.release_time_s;
  const int n = std::min<int>(8, static_cast<int>(truth.apex_heights_m.size()));
  t0 = Clock::now();
  for (int b = 0; b < n; ++b) {
    const double apex = truth.apex_times_s[b] - release;
    const double emit = b == 0 ? 0.0 : apex + a.detector_delay;
    std::this_thread::sleep_until(t0 + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(emit)));
    worker.Submit({0, b, truth.apex_heights_m[b], 0.001,
                   static_cast<int64_t>(std::llround(apex * 1e6))});
  }
  std::this_thread::sleep_for(std::chrono::seconds(2));
  worker.Stop();
  if (worker.stats().errors > 0)
    std::printf("fit errors: %d, last: %s\n", worker.stats().errors,
                worker.stats().last_error.c_str());
  std::printf("fit_bench --realtime: %s model, %s from %.2f m, peaks emitted %.0f ms after their "
              "apex, %d simulations per update at most\n\n",
              a.model.c_str(), ball.name.c_str(), a.drop, a.detector_delay * 1000, a.per_bounce);
  std::printf("%6s %10s %12s %12s %14s %6s  %s\n", "bounce", "apex s", "update s",
              "apex->upd s", "next apex s", "sims", "in time");
  std::vector<double> lat;
  int late = 0;
  for (int b = 1; b < n; ++b) {
    const double apex = truth.apex_times_s[b] - release;
    const double next = b + 1 < static_cast<int>(truth.apex_times_s.size())
                            ? truth.apex_times_s[b + 1] - release
                            : NAN;
    std::lock_guard<std::mutex> lock(m);
    auto it = update_at.find(b);
    if (it == update_at.end()) {
      std::printf("%6d %10.3f %12s %12s %14.3f %6s  %s\n", b, apex, "-", "-", next, "-",
                  "superseded");
      if (b <= 5) ++late;
      continue;
    }
    const double l = it->second - apex;
    lat.push_back(l);
    const bool ok = !(it->second >= next);
    if (b <= 5 && !ok) ++late;
    std::printf("%6d %10.3f %12.3f %12.3f %14.3f %6d  %s\n", b, apex, it->second, l, next,
                evals[b], ok ? "yes" : "NO");
  }
  std::sort(lat.begin(), lat.end());
  const double median = lat.empty() ? NAN : lat[lat.size() / 2];
  std::printf("\nmedian apex->update %.3f s over %zu updates; first five in time: %s\n", median,
              lat.size(), late == 0 ? "yes" : "NO");
  return late == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = Parse(argc, argv);
  try {
    return a.realtime ? Realtime(a) : a.law ? LawSearches(a) : Searches(a);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fit_bench: error: %s\n", e.what());
    return 1;
  }
}
