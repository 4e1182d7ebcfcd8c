#pragma once
// Test helper for the calibrator and bounce detector: tracker-like observations of a
// point-mass drop (model/point_mass_drop.h: gravity, quadratic drag, restitution e(v), the
// physics `bouncefit synth` renders), seen by a rolled camera with a known scale, averaged
// over the exposure, with Gaussian centre noise; and scoring of the detector's peaks
// against the truth (found apexes, false peaks, height error, latency).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <ostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "detect/bounce_detector.h"
#include "model/ball_preset.h"
#include "model/point_mass_drop.h"
#include "track/ball_observation.h"

namespace bouncefit::testing {

struct SimOptions {
  std::string ball = "pingpong";
  double drop_m = 1.0;
  double fps = 120;
  double roll_deg = 0;
  double px_per_m = 300;
  double noise_px = 0.15;
  double hold_s = 0.3;
  double after_rest_s = 0.5;
  double exposure_frac = 0.5;  // exposure time / frame period
  unsigned seed = 1;
  double floor_y = 560, x0 = 330;  // unrolled image position of the floor and the drop line
  double width = 660, height = 600;
  std::vector<std::pair<double, double>> gaps;  // [t0, t1) with no detection, seconds
  double missing_fraction = 0;  // random frames with no detection
  double start_s = 0;           // stream clock at frame 0
  // Beyond a drop from rest: a throw (m/s, up and right) and a clip that begins this long
  // after the release (mid-bounce: no hold seen).
  double launch_up_mps = 0, launch_right_mps = 0;
  double begin_after_release_s = 0;
};

struct SimClip {
  SimOptions options;
  PointMassDropResult truth;
  double radius_px = 0;
  std::vector<BallObservation> obs;
};

inline void SimImagePoint(const SimOptions& o, double height_bottom_m, double radius_m,
                          double* x, double* y, double right_m = 0) {
  // Unrolled: straight down is +y. Then rotate about the image centre so that true down
  // becomes (sin roll, cos roll).
  const double ux = o.x0 + right_m * o.px_per_m;
  const double uy = o.floor_y - (height_bottom_m + radius_m) * o.px_per_m;
  const double cx = (o.width - 1) / 2, cy = (o.height - 1) / 2;
  const double r = o.roll_deg * std::numbers::pi / 180;
  const double dx = ux - cx, dy = uy - cy;
  *x = cx + std::cos(r) * dx + std::sin(r) * dy;
  *y = cy - std::sin(r) * dx + std::cos(r) * dy;
}

// The drop MakeSimClip renders for `o` (release, impacts, apexes), known before the clip.
inline PointMassDropResult SimTruth(const SimOptions& o) {
  PointMassDropConfig pc;
  pc.ball = ResolveBallPreset(o.ball);
  pc.drop_height_m = o.drop_m;
  pc.hold_s = o.hold_s;
  return SimulatePointMassDrop(pc);
}

inline SimClip MakeSimClip(const SimOptions& o, int64_t frame_offset = 0) {
  SimClip clip;
  clip.options = o;
  PointMassDropConfig c;
  c.ball = ResolveBallPreset(o.ball);
  c.drop_height_m = o.drop_m;
  const double begin = o.begin_after_release_s;
  c.hold_s = begin > 0 ? 0.0 : o.hold_s;
  c.launch_speed_mps = o.launch_up_mps;
  c.end_time_s = c.hold_s + begin + 8;
  clip.truth = SimulatePointMassDrop(c);
  const double end = (clip.truth.comes_to_rest ? clip.truth.rest_time_s : clip.truth.end_time_s) +
                     o.after_rest_s;
  clip.radius_px = c.ball.radius_m() * o.px_per_m;
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0, o.noise_px);
  std::uniform_real_distribution<double> uni(0, 1);
  const int frames = static_cast<int>((end - begin) * o.fps) + 1;
  for (int i = 0; i < frames; ++i) {
    const double t = i / o.fps + begin;  // on the drop's clock
    BallObservation b;
    b.frame = frame_offset + i;
    b.utime = static_cast<int64_t>(std::llround((o.start_s + t - begin) * 1e6));
    bool hidden = o.missing_fraction > 0 && uni(rng) < o.missing_fraction;
    for (const auto& g : o.gaps) hidden = hidden || (t >= g.first && t < g.second);
    // Exposure average of the centre (8 sub-exposures).
    const double exp_s = o.exposure_frac / o.fps;
    double sx = 0, sy = 0;
    const int n_sub = 8;
    for (int k = 0; k < n_sub; ++k) {
      const double ts = t + exp_s * ((k + 0.5) / n_sub - 0.5);
      double x, y;
      SimImagePoint(o, clip.truth.At(ts).height_m, c.ball.radius_m(), &x, &y,
                    o.launch_right_mps * std::max(0.0, ts - c.hold_s));
      sx += x;
      sy += y;
    }
    const double nx = noise(rng), ny = noise(rng);
    if (hidden) {
      clip.obs.push_back(b);
      continue;
    }
    b.found = true;
    b.cx = static_cast<float>(sx / n_sub + nx);
    b.cy = static_cast<float>(sy / n_sub + ny);
    b.radius_px = static_cast<float>(clip.radius_px);
    b.w = b.h = static_cast<float>(2 * clip.radius_px);
    b.x = b.cx - b.radius_px;
    b.y = b.cy - b.radius_px;
    b.score = 1;
    clip.obs.push_back(b);
  }
  return clip;
}

// A drop whose first fall is not a clean fall from rest: the hand pushes the ball down as it
// lets go (push_mps), or the fall's centres scatter by fall_noise_px more than the rest (a
// fall smeared at 24 fps). 1 m, 390 px/m, 0.4 px of noise, exposure 0.8 of the frame.
struct FirstFall {
  std::string ball;
  double fps;
  double push_mps;       // 0: from rest
  double fall_noise_px;  // 0: none
  unsigned seed;
};

// Names a case in GoogleTest's messages (found by argument-dependent lookup).
inline void PrintTo(const FirstFall& c, std::ostream* os) {
  *os << c.ball << " at " << c.fps << " fps, pushed " << c.push_mps << " m/s, fall noise "
      << c.fall_noise_px << " px, seed " << c.seed;
}

inline SimClip MakeFirstFallClip(const FirstFall& c) {
  SimOptions o;
  o.ball = c.ball;
  o.fps = c.fps;
  o.noise_px = 0.4;
  o.px_per_m = 390;
  o.exposure_frac = 0.8;
  o.seed = c.seed;
  o.launch_up_mps = -c.push_mps;
  SimClip clip = MakeSimClip(o);
  if (c.fall_noise_px > 0) {
    std::mt19937 rng(c.seed * 7);
    std::normal_distribution<double> noise(0, c.fall_noise_px);
    const double impact = clip.truth.impact_times_s.at(0);
    for (auto& b : clip.obs) {
      const double t = b.utime * 1e-6;
      if (b.found && t > o.hold_s + 0.5 / o.fps && t < impact - 0.5 / o.fps)
        b.cy += static_cast<float>(noise(rng));
    }
  }
  return clip;
}

// Apex of the truth (bounce index b) in stream seconds.
inline double SimApexTime(const SimClip& c, size_t b) {
  return c.options.start_s + c.truth.apex_times_s[b] - c.options.begin_after_release_s;
}

struct PeakScore {
  int truth_over_1cm = 0;    // true apexes above 1 cm (bounce 0 included)
  int found_over_1cm = 0;    // of those, matched by an emitted peak
  int false_peaks = 0;       // emitted peaks matching no true apex
  double max_err_mm = 0;     // worst |height error| over matched apexes
  double rms_err_rebounds_mm = 0;  // RMS height error over matched bounces >= 1
  int rebounds = 0;
  bool within_tolerance = true;  // every matched error <= max(2 mm, 1%)
  std::vector<double> latency_frames;  // bounces >= 1: emission - true apex, frames
  double bounce0_latency_from_impact_frames = NAN;
  std::string report;        // one line per peak, for failure messages
};

inline double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The truth a score needs: apex times (stream seconds) and heights, impact times.
struct TruthApexes {
  double fps = 120;
  std::vector<double> apex_t_s, apex_h_m, impact_t_s;
};

inline TruthApexes TruthOf(const SimClip& c) {
  TruthApexes t;
  t.fps = c.options.fps;
  const double begin = c.options.begin_after_release_s;
  // Begun after the release: the first apex in view after an impact out of view is
  // bounce 1 to the detector (it cannot know how many came before).
  if (begin > 0) {
    t.apex_t_s.push_back(-100);
    t.apex_h_m.push_back(0);
  }
  for (size_t b = 0; b < c.truth.apex_times_s.size(); ++b) {
    if (c.truth.apex_times_s[b] < begin) continue;
    t.apex_t_s.push_back(SimApexTime(c, b));
    t.apex_h_m.push_back(c.truth.apex_heights_m[b]);
  }
  for (double i : c.truth.impact_times_s)
    if (i >= begin) t.impact_t_s.push_back(c.options.start_s + i - begin);
  return t;
}

// Peaks of one sequence against its truth: a peak matches the true apex with the same
// bounce index whose time is within 3 frames of the peak's apex time.
// Apexes at or below min_truth_m are not required (a peak matching one still counts).
inline PeakScore ScorePeaks(const TruthApexes& c, const std::vector<BouncePeak>& peaks,
                            double min_truth_m = 0.01) {
  PeakScore s;
  const double frame = 1.0 / c.fps;
  std::vector<bool> matched(c.apex_h_m.size(), false);
  for (const auto& p : peaks) {
    const auto b = static_cast<size_t>(p.bounce);
    const double t_apex = static_cast<double>(p.apex_utime) * 1e-6;
    if (b >= c.apex_h_m.size() || std::abs(t_apex - c.apex_t_s[b]) > 3 * frame) {
      ++s.false_peaks;
      s.report += fmt::format("bounce {} at {:.4f} s: {:.4f} m FALSE\n", b, t_apex, p.height_m);
      continue;
    }
    matched[b] = true;
    const double truth = c.apex_h_m[b];
    const double err = p.height_m - truth;
    s.max_err_mm = std::max(s.max_err_mm, std::abs(err) * 1e3);
    if (std::abs(err) > std::max(0.002, 0.01 * truth)) s.within_tolerance = false;
    const double emitted = static_cast<double>(p.emitted_utime) * 1e-6;
    const double lat = (emitted - c.apex_t_s[b]) / frame;
    if (b >= 1) {
      s.latency_frames.push_back(lat);
      s.rms_err_rebounds_mm = std::sqrt((s.rms_err_rebounds_mm * s.rms_err_rebounds_mm * s.rebounds +
                                         err * err * 1e6) / (s.rebounds + 1));
      ++s.rebounds;
    } else if (!c.impact_t_s.empty()) {
      s.bounce0_latency_from_impact_frames = (emitted - c.impact_t_s[0]) / frame;
    }
    s.report += fmt::format("bounce {}: {:.4f} m (truth {:.4f}, err {:+.2f} mm) latency {:.2f} frames\n", b,
                            p.height_m, truth, err * 1e3, lat);
  }
  for (size_t b = 0; b < matched.size(); ++b) {
    if (c.apex_h_m[b] <= min_truth_m) continue;
    ++s.truth_over_1cm;
    if (matched[b]) {
      ++s.found_over_1cm;
    } else {
      s.report += fmt::format("MISSED bounce {}: {:.4f} m at {:.4f} s\n", b, c.apex_h_m[b], c.apex_t_s[b]);
    }
  }
  return s;
}

inline PeakScore ScorePeaks(const SimClip& c, const std::vector<BouncePeak>& peaks) {
  return ScorePeaks(TruthOf(c), peaks);
}

inline double MaxOf(const std::vector<double>& v) {
  double m = NAN;
  for (double x : v) m = std::isnan(m) ? x : std::max(m, x);
  return m;
}

// Runs a detector over a clip, returns the peaks (all sequences) and the events. Any detector
// with BounceDetector's Push and Finish (detect/retiming_detector.h too).
template <class Detector>
std::vector<BouncePeak> RunDetector(Detector& d, const std::vector<BallObservation>& obs,
                                    std::vector<DetectorEvent>* all_events = nullptr) {
  std::vector<BouncePeak> peaks;
  auto take = [&](const std::vector<DetectorEvent>& ev) {
    for (const auto& e : ev) {
      if (e.kind == DetectorEvent::Kind::kPeak) peaks.push_back(e.peak);
      if (all_events) all_events->push_back(e);
    }
  };
  for (const auto& o : obs) take(d.Push(o));
  take(d.Finish());
  return peaks;
}

}  // namespace bouncefit::testing
