// Sensitivity of the soft-body ball's bounce heights to each coefficient (docs/MODEL.md):
// starting from a ball's stored coefficients (model/presets/soft_ball_<ball>.json), every
// coefficient in turn is swept across its whole range (the others fixed) and the first
// three bounce heights are compared with the start's. Also the chaos floor: how much the
// heights move when one coefficient changes by a few parts per million.
//
//   build/bench/soft_ball_sensitivity_bench [--ball pingpong] [--points 9] [--drop 1.0]
//
// Prints a markdown table. "identical" means every sweep point gave bit-identical heights:
// the coefficient does not reach the simulation at all.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
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

CoefficientValues Stored(const std::string& ball) {
  const std::string path = std::filesystem::path(__FILE__).parent_path().parent_path().string() +
                           "/model/presets/soft_ball_" + ball + ".json";
  std::ifstream in(path);
  if (!in) return {};
  const auto j = nlohmann::json::parse(in);
  CoefficientValues v;
  for (const auto& [k, x] : j.at("coefficients").items()) v[k] = x.get<double>();
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  std::string ball = "pingpong";
  int points = 9;
  double drop = 1.0;
  const char* usage = "usage: %s [--ball NAME] [--points N] [--drop M]\n";
  for (int i = 1; i < argc; i += 2) {
    if (const auto end = bouncefit::bench::HelpOrMissingValue(argc, argv, i, usage)) return *end;
    if (!std::strcmp(argv[i], "--ball")) ball = argv[i + 1];
    else if (!std::strcmp(argv[i], "--points")) points = std::max(2, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--drop")) drop = std::atof(argv[i + 1]);
    else return bouncefit::bench::PrintUsage(usage, argv[0], false);
  }
  const auto preset = FindBallPreset(ball);
  if (!preset) return 2;
  const SoftBallModel model(*preset);
  std::string error;
  const CoefficientValues base = model.Complete(Stored(ball), &error);
  if (!error.empty()) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  SimulationOptions o;
  o.drop_height_m = drop;
  o.duration_s = 6;
  o.min_bounce_height_m = 0.002;
  const SimulationResult b = model.Simulate(base, o);
  if (!b.ok || b.bounce_heights_m.size() < 3) {
    std::fprintf(stderr, "start point fails: %s\n", b.failure.c_str());
    return 1;
  }
  const std::vector<double> h0(b.bounce_heights_m.begin(), b.bounce_heights_m.begin() + 3);
  std::printf("ball %s from %.2f m, stored coefficients; start heights %.4f %.4f %.4f m\n",
              ball.c_str(), drop, h0[0], h0[1], h0[2]);

  // Chaos floor: relative changes of 1..8 ppm of one coefficient.
  {
    double spread[3] = {0, 0, 0};
    for (const char* name : {"linear_stiffness", "contact_hardness", "volume_conservation"})
      for (int k = 1; k <= 8; ++k) {
        CoefficientValues v = base;
        v[name] *= 1 + 1e-6 * k;
        const SimulationResult r = model.Simulate(v, o);
        for (size_t i = 0; i < 3 && i < r.bounce_heights_m.size(); ++i)
          spread[i] = std::max(spread[i], std::abs(r.bounce_heights_m[i] / h0[i] - 1));
      }
    std::printf("chaos floor (largest change for 1-8 ppm changes of linear_stiffness, "
                "contact_hardness, volume_conservation): %.2f%% %.2f%% %.2f%%\n\n",
                100 * spread[0], 100 * spread[1], 100 * spread[2]);
  }

  std::printf("| coefficient | start | swept | bounce 1 (%%) | bounce 2 (%%) | bounce 3 (%%) | failed | +-5%% of range: bounces 1, 2, 3 (%%) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const auto& s : model.Coefficients()) {
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    int failed = 0;
    bool identical = true;
    std::vector<double> values;
    if (s.discrete)
      for (double x = s.lower; x <= s.upper + 1e-9; x += 1) values.push_back(x);
    else
      for (int k = 0; k < points; ++k) values.push_back(s.lower + (s.upper - s.lower) * k / (points - 1));
    auto record = [&](const SimulationResult& r, double* l, double* h) {
      if (!r.ok || r.bounce_heights_m.size() < 3) return false;
      for (int i = 0; i < 3; ++i) {
        const double d = r.bounce_heights_m[size_t(i)] / h0[size_t(i)] - 1;
        l[i] = std::min(l[i], d);
        h[i] = std::max(h[i], d);
      }
      return true;
    };
    for (double x : values) {
      CoefficientValues v = base;
      v[s.name] = x;
      const SimulationResult r = model.Simulate(v, o);
      if (!record(r, lo, hi)) {
        ++failed;
        identical = false;
      } else if (r.bounce_heights_m[0] != h0[0] || r.bounce_heights_m[1] != h0[1] ||
                 r.bounce_heights_m[2] != h0[2]) {
        identical = false;
      }
    }
    // Local: +-5% of the range around the start (inside the bounds).
    double llo[3] = {0, 0, 0}, lhi[3] = {0, 0, 0};
    int lfailed = 0;
    for (double sign : {-1.0, 1.0}) {
      CoefficientValues v = base;
      const double step = s.discrete ? 1 : 0.05 * (s.upper - s.lower);
      v[s.name] = std::clamp(base.at(s.name) + sign * step, s.lower, s.upper);
      if (!record(model.Simulate(v, o), llo, lhi)) ++lfailed;
    }
    // Each bounce's change in percent, lowest..highest ("0": none), over the sweep and locally.
    std::string swept_changes, local_changes;
    for (int i = 0; i < 3; ++i) {
      swept_changes += fmt::format("{}{}", i ? " | " : "",
                                   lo[i] == 0 && hi[i] == 0 ? "0" : fmt::format("{:+.1f}..{:+.1f}", 100 * lo[i], 100 * hi[i]));
      local_changes += fmt::format("{}{}", i ? ", " : "",
                                   llo[i] == 0 && lhi[i] == 0 ? "0" : fmt::format("{:+.1f}..{:+.1f}", 100 * llo[i], 100 * lhi[i]));
    }
    if (lfailed) local_changes += fmt::format(" ({} failed)", lfailed);
    const std::string swept = fmt::format("{:g}..{:g} ({})", s.lower, s.upper, values.size());
    if (identical)
      fmt::print("| {} | {:.4g} | {} | identical | identical | identical | 0 | identical |\n", s.name, base.at(s.name),
                 swept);
    else
      fmt::print("| {} | {:.4g} | {} | {} | {} | {} |\n", s.name, base.at(s.name), swept, swept_changes, failed,
                 local_changes);
    std::fflush(stdout);
  }
  return 0;
}
