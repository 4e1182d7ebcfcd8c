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

std::string Range(double lo, double hi) {
  char buf[64];
  if (lo == 0 && hi == 0) return "0";
  std::snprintf(buf, sizeof buf, "%+.1f..%+.1f", 100 * lo, 100 * hi);
  return buf;
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
    char local[128];
    std::snprintf(local, sizeof local, "%s, %s, %s%s", Range(llo[0], lhi[0]).c_str(),
                  Range(llo[1], lhi[1]).c_str(), Range(llo[2], lhi[2]).c_str(),
                  lfailed ? (" (" + std::to_string(lfailed) + " failed)").c_str() : "");
    char start[32], swept[64];
    std::snprintf(start, sizeof start, "%.4g", base.at(s.name));
    std::snprintf(swept, sizeof swept, "%g..%g (%zu)", s.lower, s.upper, values.size());
    if (identical)
      std::printf("| %s | %s | %s | identical | identical | identical | 0 | identical |\n",
                  s.name.c_str(), start, swept);
    else
      std::printf("| %s | %s | %s | %s | %s | %s | %d | %s |\n", s.name.c_str(), start, swept,
                  Range(lo[0], hi[0]).c_str(), Range(lo[1], hi[1]).c_str(),
                  Range(lo[2], hi[2]).c_str(), failed, local);
    std::fflush(stdout);
  }
  return 0;
}
