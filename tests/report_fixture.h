#pragma once
// A plausible run output directory (docs/FORMATS.md) computed from physics, for the report
// tests: a ball dropped from 1 m bounces with restitution 0.8 (parabolic arcs, g = 9.81),
// seen at 120 fps by a camera with 400 px/m and the floor line at 460 px. The apexes,
// calibration, fit updates and simulated trajectory are consistent with that motion.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace bouncefit::testing {

struct ReportFixtureOptions {
  bool calibration = true;
  bool fits = true;        // fit.jsonl with updates after bounces 1..3 and a final fit
  bool simulated = true;   // simulated.csv
  bool exports = true;     // fit_export.cc and coefficients.json
  double duration_s = 3.0;
};

struct ReportFixtureTruth {
  double px_per_m = 400, floor_px = 460, radius_m = 0.02, g = 9.81, restitution = 0.8;
  double release_t_s = 0.1, release_height_m = 1.0;
  std::vector<double> apex_t_s, apex_height_m;  // bounce 0 (release), 1, 2, ...
  std::vector<double> impact_t_s;
};

// Height of the ball bottom (m) at time t for a drop with restitution e.
inline double FixtureHeight(const ReportFixtureTruth& truth, double e, double t) {
  if (t <= truth.release_t_s) return truth.release_height_m;
  double t0 = truth.release_t_s;
  double v_up = 0, h0 = truth.release_height_m;  // state at the start of the current arc
  for (;;) {
    // Time to hit the floor from height h0 with upward speed v_up.
    const double t_hit = (v_up + std::sqrt(v_up * v_up + 2 * truth.g * h0)) / truth.g;
    if (t < t0 + t_hit || t_hit < 1e-4) {
      const double dt = t - t0;
      return std::max(0.0, h0 + v_up * dt - 0.5 * truth.g * dt * dt);
    }
    const double v_impact = truth.g * t_hit - v_up;
    t0 += t_hit;
    v_up = e * v_impact;
    h0 = 0;
  }
}

inline ReportFixtureTruth WriteReportFixture(const std::filesystem::path& dir,
                                             const ReportFixtureOptions& opt = {}) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  ReportFixtureTruth tr;
  // Apexes and impacts in closed form.
  tr.apex_t_s.push_back(tr.release_t_s);
  tr.apex_height_m.push_back(tr.release_height_m);
  double t = tr.release_t_s + std::sqrt(2 * tr.release_height_m / tr.g);
  double v = std::sqrt(2 * tr.g * tr.release_height_m);
  while (t < opt.duration_s) {
    tr.impact_t_s.push_back(t);
    v *= tr.restitution;
    const double apex_t = t + v / tr.g;
    const double apex_h = v * v / (2 * tr.g);
    if (apex_t + 0.1 > opt.duration_s || apex_h < 0.02) break;
    tr.apex_t_s.push_back(apex_t);
    tr.apex_height_m.push_back(apex_h);
    t += 2 * v / tr.g;
  }
  const double r_px = tr.radius_m * tr.px_per_m;

  std::ofstream track(dir / "track.csv");
  track << "frame,t_s,found,cx_px,cy_px,x_px,y_px,w_px,h_px\n";
  const int frames = static_cast<int>(opt.duration_s * 120);
  for (int f = 0; f < frames; ++f) {
    const double ts = f / 120.0;
    if (f % 97 == 50) {  // the tracker loses the ball now and then
      track << f << "," << ts << ",0,,,,,,\n";
      continue;
    }
    const double h = FixtureHeight(tr, tr.restitution, ts);
    const double squash = h < 0.004 ? 1.18 : 1.0;  // flattened against the floor
    const double w_px = 2 * r_px * std::sqrt(squash), h_px = 2 * r_px / std::sqrt(squash);
    const double cx = 320.0, cy = tr.floor_px - h * tr.px_per_m - h_px / 2;
    track << f << "," << ts << ",1," << cx << "," << cy << "," << std::round(cx - w_px / 2) << ","
          << std::round(cy - h_px / 2) << "," << std::round(w_px) << "," << std::round(h_px)
          << "\n";
  }

  std::ofstream peaks(dir / "peaks.csv");
  peaks << "bounce,t_s,height_m,height_px,flight_height_m,emitted_t_s\n";
  for (size_t i = 0; i < tr.apex_t_s.size(); ++i) {
    const double h = tr.apex_height_m[i];
    peaks << i << "," << tr.apex_t_s[i] << "," << h << "," << h * tr.px_per_m << ",";
    if (i >= 1 && i < tr.impact_t_s.size()) {
      const double dt = tr.impact_t_s[i] - tr.impact_t_s[i - 1];
      peaks << tr.g * dt * dt / 8;
    }
    peaks << "," << tr.apex_t_s[i] + 0.05 << "\n";
  }

  if (opt.calibration) {
    std::ofstream(dir / "calibration.json")
        << "{\"px_per_m\": 400.0, \"px_per_m_sigma\": 1.2, \"roll_rad\": 0.0, "
           "\"roll_sigma_rad\": 0.0008, \"floor_px\": 460.0, \"floor_sigma_px\": 0.4, "
           "\"method\": \"free-fall\", \"samples\": 48, \"t_s\": 0.55}\n";
  }
  const int bounces = static_cast<int>(tr.apex_height_m.size()) - 1;
  if (opt.fits) {
    std::ofstream fit(dir / "fit.jsonl");
    const double truth_e[] = {0.8, 0.002};
    for (int after = 1; after <= bounces; ++after) {
      const bool final = after == bounces;
      const double k = 1.0 / (after + 1);  // converges towards the truth
      const double e = truth_e[0] - 0.06 * k, e_v = truth_e[1] + 0.004 * k;
      std::ostringstream rec, sim;
      for (int i = 1; i <= after; ++i) {
        rec << (i > 1 ? "," : "") << tr.apex_height_m[i];
        sim << (i > 1 ? "," : "") << tr.release_height_m * std::pow(e * e, i);
      }
      fit << "{\"t_s\":" << tr.apex_t_s[after] + 0.05 << ",\"sequence\":0,\"after_bounce\":"
          << after << ",\"final\":" << (final ? "true" : "false")
          << ",\"model\":\"point-mass\",\"method\":\"nlopt-bobyqa\",\"coefficients\":["
          << "{\"name\":\"restitution\",\"value\":" << e << ",\"sigma\":" << 0.01 * k
          << ",\"identifiable\":true},"
          << "{\"name\":\"restitution_per_mps\",\"value\":" << e_v << ",\"sigma\":" << 0.001 * k
          << ",\"identifiable\":true},"
          << "{\"name\":\"spin_damping\",\"value\":0.5,\"sigma\":null,\"identifiable\":false}],"
          << "\"recorded_m\":[" << rec.str() << "],\"simulated_m\":[" << sim.str() << "],\"residual_m\":"
          << 0.004 * k << ",\"evaluations\":" << 40 * after << ",\"wall_time_s\":" << 0.1 * after
          << ",\"time_step_s\":0.008333333,\"iterations\":4}\n";
    }
  }
  if (opt.simulated) {
    std::ofstream sim(dir / "simulated.csv");
    sim << "t_s,height_m\n";
    for (int f = 0; f < frames; ++f) {
      const double ts = f / 120.0;
      sim << ts << "," << FixtureHeight(tr, 0.79, ts) << "\n";
    }
  }
  if (opt.exports) {
    // As fit/fit_export.h writes them.
    std::ofstream(dir / "coefficients.json")
        << "{\"model\": \"point-mass\", \"coefficients\": {\"restitution\": {\"value\": "
           "0.79, \"sigma\": 0.002, \"identifiable\": true, \"unit\": \"\", \"note\": "
           "\"e at low impact speed\"}, \"restitution_per_mps\": {\"value\": 0.003, "
           "\"sigma\": 0.001, \"identifiable\": true, \"unit\": \"s/m\", \"note\": \"\"}}}\n";
    std::ofstream(dir / "soft_body_config.cc")
        << "// Coefficients fitted by bouncefit for a point-mass ball.\n"
           "const double kRestitution = 0.79;  // -\n"
           "const double kRestitutionPerMps = 0.003;  // s/m\n";
  }
  std::ofstream(dir / "summary.json")
      << "{\"input\": \"fixture (parabolic arcs)\", \"ball\": \"pingpong\", \"frames\": " << frames
      << ", \"dropped_frames\": 0, \"duration_s\": " << opt.duration_s
      << ", \"wall_time_s\": 3.1, \"timings_ms\": {\"track\": 1.5, \"detect\": 0.1}}\n";
  return tr;
}

}  // namespace bouncefit::testing
