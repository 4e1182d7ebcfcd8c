#pragma once
// A `bouncefit run` of a rendered clip scored against its truth (test-only): every apex of
// min_height_m or more, the ball in view, matched by time to a peaks.csv row within max(2 mm, 2%), rows that
// match no apex counted as false, and each drop's scale (summary.json) against the truth's.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "msgs/peaks_csv.h"
#include "synth/synth_truth.h"
#include "tests/test_support.h"

namespace bouncefit::testing {

struct SynthRunScore {
  int wanted = 0, found = 0, off = 0, missed = 0, false_rows = 0;
  // Per truth drop (one for a clip of one drop): the scale the run measured over the truth's
  // (0: no drop of the run matched it), and the run's drop number its rows carry (-1: none).
  std::vector<double> scale_ratio;
  std::vector<int> run_drop;
  std::string table;  // one line per apex and per false row
};

inline SynthRunScore ScoreSynthRun(const SynthTruth& truth, const std::filesystem::path& out_dir,
                                   double min_height_m = 0.02) {
  SynthRunScore s;
  const std::vector<PeaksCsvRow> rows = ReadPeaksCsv(out_dir / "peaks.csv");
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(out_dir / "summary.json"));
  const double end_s = truth.frame_count / truth.fps;
  std::vector<SynthTruthDrop> drops = truth.drops;
  if (drops.empty()) {
    SynthTruthDrop d;
    d.px_per_m = truth.px_per_m;
    d.release_t_s = truth.release_t_s;
    d.apex_times_s = truth.apex_times_s;
    d.apex_heights_m = truth.apex_heights_m;
    d.impact_times_s = truth.impact_times_s;
    d.rest_t_s = end_s;
    drops.push_back(d);
  }
  std::vector<bool> used(rows.size(), false);
  s.run_drop.assign(drops.size(), -1);
  for (size_t k = 0; k < drops.size(); ++k) {
    const SynthTruthDrop& d = drops[k];
    for (size_t a = 0; a < d.apex_times_s.size(); ++a) {
      const double t = d.apex_times_s[a], h = d.apex_heights_m[a];
      if (t < 1.5 / truth.fps || t > end_s - 1.5 / truth.fps) continue;
      int best = -1;
      for (size_t j = 0; j < rows.size(); ++j)
        if (std::abs(rows[j].t_s - t) < 0.06 && (best < 0 || std::abs(rows[j].t_s - t) < std::abs(rows[best].t_s - t)))
          best = static_cast<int>(j);
      if (best >= 0) used[static_cast<size_t>(best)] = true, s.run_drop[k] = rows[static_cast<size_t>(best)].drop;
      // An apex out of the picture (a throw gone out of view) is no one's to see.
      const auto at = std::min_element(truth.frames.begin(), truth.frames.end(), [&](const auto& x, const auto& y) {
        return std::abs(x.t_s - t) < std::abs(y.t_s - t);
      });
      if (h < min_height_m || (at != truth.frames.end() && !at->fully_in_view)) continue;
      ++s.wanted;
      if (best < 0) {
        ++s.missed;
        s.table += fmt::format("  drop {} apex {} at {:.3f} s: {:.4f} m MISSED\n", k, a, t, h);
      } else {
        const double got = rows[static_cast<size_t>(best)].height_m;
        const bool ok = std::abs(got - h) <= std::max(0.002, 0.02 * h);
        ++(ok ? s.found : s.off);
        s.table += fmt::format("  drop {} apex {} at {:.3f} s: {:.4f} m, run {:.4f} m (drop {}){}\n", k, a, t, h, got,
                               rows[static_cast<size_t>(best)].drop, ok ? "" : " OFF");
      }
    }
  }
  for (size_t j = 0; j < rows.size(); ++j) {
    if (used[j]) continue;
    ++s.false_rows;
    s.table += fmt::format("  FALSE row: bounce {} at {:.3f} s, {:.4f} m (drop {})\n", rows[j].bounce, rows[j].t_s,
                           rows[j].height_m, rows[j].drop);
  }
  // Each truth drop's scale: the run's drop whose first impact falls within it.
  s.scale_ratio.assign(drops.size(), 0);
  for (const auto& rd : summary["drops"]) {
    if (rd["impacts"].empty() || !rd["px_per_m"].is_number()) continue;
    const double t = rd["impacts"][0]["t_s"].get<double>();
    for (size_t k = 0; k < drops.size(); ++k)
      if (t >= drops[k].release_t_s - 0.5 && t <= drops[k].rest_t_s + 0.1 && s.scale_ratio[k] == 0)
        s.scale_ratio[k] = rd["px_per_m"].get<double>() / drops[k].px_per_m;
  }
  for (size_t k = 0; k < drops.size(); ++k) {
    s.table += fmt::format("  drop {}: scale {:.4f} of the truth's\n", k, s.scale_ratio[k]);
  }
  return s;
}

// The frames in flight (the whole ball in view, after the release, before it rests) and those
// of them track.csv does not find; `lost` lists the first few.
struct InFlightScore {
  int in_flight = 0, lost = 0;
  std::string lost_frames;
};

inline InFlightScore ScoreInFlight(const SynthTruth& truth, const std::filesystem::path& out_dir) {
  InFlightScore s;
  const auto track = ReadCsv(out_dir / "track.csv");
  const double rest = truth.comes_to_rest ? truth.rest_t_s : 1e9;
  for (const auto& f : truth.frames) {
    if (!f.fully_in_view || f.t_s <= truth.release_t_s + 0.01 || f.t_s >= rest) continue;
    ++s.in_flight;
    const auto i = static_cast<size_t>(f.index);
    if (i >= track.size() || track[i].at("found") != "1")
      if (++s.lost <= 5) s.lost_frames.append(" ").append(std::to_string(f.index));
  }
  return s;
}

// Prints the score under `name` and expects what every rendered kind must show: at least
// `at_least` apexes wanted, each found within max(2 mm, 2%), no false row, the scale within 2%.
inline void ExpectEveryApex(const char* name, const SynthRunScore& s, int at_least) {
  std::printf("%s: %d of %d apexes >= 2 cm within max(2 mm, 2%%), %d off, %d missed, %d false\n%s", name, s.found,
              s.wanted, s.off, s.missed, s.false_rows, s.table.c_str());
  EXPECT_GE(s.wanted, at_least) << s.table;
  EXPECT_EQ(s.found, s.wanted) << s.table;
  EXPECT_EQ(s.false_rows, 0) << s.table;
  ASSERT_FALSE(s.scale_ratio.empty());
  EXPECT_NEAR(s.scale_ratio[0], 1.0, 0.02) << s.table;
}

// A run's track.csv against the truth, frame by frame in flight (released, the ball all in
// view, not at rest): the frames without the ball where it was (not found, or found further
// than its radius from its centre: on something else).
struct FlightFrames {
  int in_flight = 0, without_ball = 0;
  std::string which;  // their frame numbers
};

inline FlightFrames ScoreFramesInFlight(const SynthTruth& truth, const std::filesystem::path& out_dir) {
  FlightFrames f;
  const auto rows = ReadCsv(out_dir / "track.csv");
  const double rest = truth.comes_to_rest ? truth.rest_t_s : 1e9;
  for (size_t i = 0; i < truth.frames.size() && i < rows.size(); ++i) {
    const SynthTruthFrame& t = truth.frames[i];
    if (!t.fully_in_view || t.t_s <= truth.release_t_s + 0.01 || t.t_s >= rest) continue;
    ++f.in_flight;
    const auto& r = rows[i];
    if (r.at("found") != "1" ||
        std::hypot(std::stod(r.at("cx_px")) - t.cx, std::stod(r.at("cy_px")) - t.cy) > truth.radius_px)
      ++f.without_ball, f.which += " " + std::to_string(i);
  }
  return f;
}

}  // namespace bouncefit::testing
