// Speed of the soft-body ball model: simulated seconds per second of one core,
// for the default mesh, and how the cost grows with the mesh resolution, as ratios against
// the default mesh measured in the same run.
//
//   build/bench/soft_ball_bench [--reps N] [--ball pingpong] [--drop 1.0] [--duration 6]
//
// Every run simulates the full duration (no early stop at rest), single-threaded. CPU time
// is this thread's (CLOCK_THREAD_CPUTIME_ID), so a busy machine slows wall time but not
// the figure; wall time is printed too.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/ball_preset.h"
#include "model/soft_ball_model.h"
#include "bench/paired_options.h"

namespace {

using namespace bouncefit;

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Timing {
  double cpu_s = 0, wall_s = 0;  // per run, best of the repetitions
  bool ok = true;
  std::string failure;
  size_t bounces = 0;
};

Timing Time(const SoftBallModel& model, const CoefficientValues& values,
            const SimulationOptions& options, int reps) {
  Timing best;
  best.cpu_s = best.wall_s = 1e300;
  for (int i = 0; i < reps; ++i) {
    const double c0 = ThreadCpuSeconds();
    const auto w0 = std::chrono::steady_clock::now();
    const SimulationResult r = model.Simulate(values, options);
    const double cpu = ThreadCpuSeconds() - c0;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    best.cpu_s = std::min(best.cpu_s, cpu);
    best.wall_s = std::min(best.wall_s, wall);
    best.ok = r.ok;
    best.failure = r.failure;
    best.bounces = r.bounce_heights_m.size();
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  std::string ball = "pingpong";
  double drop = 1.0, duration = 6.0;
  const char* usage = "usage: %s [--reps N] [--ball NAME] [--drop M] [--duration S]\n";
  for (int i = 1; i < argc; i += 2) {
    if (const auto end = bouncefit::bench::HelpOrMissingValue(argc, argv, i, usage)) return *end;
    if (!std::strcmp(argv[i], "--reps")) reps = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--ball")) ball = argv[i + 1];
    else if (!std::strcmp(argv[i], "--drop")) drop = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--duration")) duration = std::atof(argv[i + 1]);
    else return bouncefit::bench::PrintUsage(usage, argv[0], false);
  }
  const auto preset = FindBallPreset(ball);
  if (!preset) {
    std::fprintf(stderr, "unknown ball %s\n", ball.c_str());
    return 2;
  }
  const SoftBallModel model(*preset);
  SimulationOptions options;
  options.drop_height_m = drop;
  options.duration_s = duration;
  options.min_bounce_height_m = -1;  // never stop early: time the whole duration

  std::printf("soft-body model speed: %s, drop %.2f m, %.1f s simulated, dt %.6f s, %d iterations, best of %d\n",
              ball.c_str(), drop, duration, model.config().time_step_s,
              model.config().position_iterations, reps);
  // Mesh generation (and its cache) is not timed: prepare every mesh first.
  std::vector<int> resolutions;
  for (const auto& s : model.Coefficients())
    if (s.name == "mesh_resolution")
      for (int f = int(s.lower); f <= int(s.upper); ++f) resolutions.push_back(f);
  const double default_resolution = [&] {
    for (const auto& s : model.Coefficients())
      if (s.name == "mesh_resolution") return s.default_value;
    return 3.0;
  }();
  for (int f : resolutions) model.Mesh({{"mesh_resolution", f}});

  const Timing base = Time(model, {}, options, reps);
  const auto base_mesh = model.Mesh({});
  std::printf("\ndefault mesh (resolution %.0f): %zu nodes, %zu tetrahedra, %zu faces\n",
              default_resolution, base_mesh->nodes.size(), base_mesh->tetras.size(),
              base_mesh->faces.size());
  std::printf("  %.3f s CPU, %.3f s wall for %.1f s: %.0fx real time per core (%.0fx by wall clock)%s\n",
              base.cpu_s, base.wall_s, duration, duration / base.cpu_s, duration / base.wall_s,
              base.ok ? "" : (" FAILED: " + base.failure).c_str());

  std::printf("\n| mesh_resolution | nodes | tetrahedra | links | CPU s per sim s | real time x | cost / default |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (int f : resolutions) {
    const CoefficientValues v{{"mesh_resolution", f}};
    const auto mesh = model.Mesh(v);
    size_t links = 0;
    {
      std::vector<std::pair<int, int>> edges;
      for (const auto& t : mesh->tetras) {
        const int e[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
        for (const auto& ed : e) {
          int a = t[size_t(ed[0])], b = t[size_t(ed[1])];
          edges.emplace_back(std::min(a, b), std::max(a, b));
        }
      }
      std::sort(edges.begin(), edges.end());
      links = size_t(std::unique(edges.begin(), edges.end()) - edges.begin());
    }
    const Timing t = Time(model, v, options, reps);
    std::printf("| %d | %zu | %zu | %zu | %.4f | %.0f | %.2f |%s\n", f, mesh->nodes.size(),
                mesh->tetras.size(), links, t.cpu_s / duration, duration / t.cpu_s,
                t.cpu_s / base.cpu_s, t.ok ? "" : (" failed: " + t.failure).c_str());
  }

  // What a fit evaluation costs: each ball's stored coefficients (model/presets/), dropped from
  // the same height until the bounces fall below 1 cm (the model's early stop).
  std::printf("\n| stored coefficients | simulated until | bounces >= 1 cm | CPU s | real time x |\n");
  std::printf("|---|---|---|---|---|\n");
  for (const char* name : {"pingpong", "wiffle", "softball", "airball"}) {
    const auto p = FindBallPreset(name);
    const SoftBallModel m(*p);
    CoefficientValues v;
    {
      std::ifstream in(std::filesystem::path(__FILE__).parent_path().parent_path() / "model" /
                       "presets" / (std::string("soft_ball_") + name + ".json"));
      if (!in) continue;
      const nlohmann::json j = nlohmann::json::parse(in);  // named: items() must not dangle
      for (const auto& [k, x] : j.at("coefficients").items()) v[k] = x.get<double>();
    }
    SimulationOptions o = options;
    o.min_bounce_height_m = 0.01;
    o.record_trajectory = true;  // to know where it stopped
    o.trajectory_rate_hz = 120;
    const SimulationResult r = m.Simulate(v, o);
    const double simulated = r.trajectory.empty() ? 0 : r.trajectory.back().t_s;
    o.record_trajectory = false;
    const Timing t = Time(m, v, o, reps);
    std::printf("| %s | %.2f s | %zu | %.4f | %.0f |%s\n", name, simulated, t.bounces, t.cpu_s,
                simulated / t.cpu_s, t.ok ? "" : (" failed: " + t.failure).c_str());
  }
  return 0;
}
