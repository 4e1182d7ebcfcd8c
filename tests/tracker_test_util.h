#pragma once
// Shared by the tracker tests: render a synth clip with known truth, run the tracker over it,
// score centres against the truth.
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "synth/synth_clip.h"
#include "synth/synth_truth.h"
#include "replay/video_file_source.h"
#include "track/look_back_tracker.h"
#include "track/tracker.h"

namespace bouncefit::testing {

struct TrackScore {
  int in_view = 0;        // frames with the ball fully in view
  int lost = 0;           // ... where the tracker found nothing
  int wrong = 0;          // frames where it reported a ball far (> max(3 px, r/2)) from the truth
  int found_total = 0;
  double rms = 0, p99 = 0, max = 0;  // centre error on in-view frames it found, px
  double mean_dx = 0, mean_dy = 0;   // bias, px
  std::string describe;
  double color_nu = 0, color_nv = 0;  // the colour the tracker ended with (chroma/luma)
  double anchor_drift = 0;            // how far it moved from the initial colour
  std::vector<BallObservation> obs;
};

// A ball dropped from (300, 60) px in a 640 x 600 frame and bouncing on the line y = 560 (60
// fps, 600 px a metre, restitution 0.8), drifting 0.5 px a frame sideways: its centre on
// frame i after i calls of Step().
struct DroppedBall {
  double r = 30;
  double x = 300, y = 60, vy = 0;  // px, px/s
  static constexpr double kFps = 60, kG = 9.81 * 600, kFloorY = 560;
  void Step() {
    x += 0.5;
    vy += kG / kFps;
    y += vy / kFps;
    if (y + r > kFloorY && vy > 0) y = 2 * (kFloorY - r) - y, vy = -0.8 * vy;
  }
};

// A disc drawn with sub-pixel centre and radius (OpenCV's 4 fractional bits, antialiased).
inline void DrawBall(cv::Mat& img, double x, double y, double r, const cv::Scalar& bgr) {
  cv::circle(img, cv::Point(static_cast<int>(std::lround(x * 16)), static_cast<int>(std::lround(y * 16))),
             static_cast<int>(r * 16), bgr, cv::FILLED, cv::LINE_AA, 4);
}

// A drawn picture as the tracker gets it: sensor noise added (drawn into 8 bits by `rng`, so
// its positive half, sigma in grey levels), stamped as frame `index` of a clip at `fps`.
inline Frame DrawnFrame(cv::Mat img, int index, double fps, cv::RNG& rng, double noise_sigma = 2) {
  cv::Mat noise(img.size(), img.type());
  rng.fill(noise, cv::RNG::NORMAL, 0, noise_sigma);
  img += noise;
  Frame f;
  f.image = img;
  f.index = index;
  f.utime = static_cast<int64_t>(std::llround(index / fps * 1e6));
  return f;
}

// YUYV (limited-range BT.601, chroma of each pixel pair averaged) from a BGR frame, the way a
// V4L2 camera delivers it.
inline cv::Mat BgrToYuyv(const cv::Mat& bgr) {
  cv::Mat ycc;
  cv::cvtColor(bgr, ycc, cv::COLOR_BGR2YCrCb);  // full range: Y, Cr, Cb
  cv::Mat out(bgr.rows, bgr.cols, CV_8UC2);
  for (int j = 0; j < bgr.rows; ++j) {
    const uint8_t* s = ycc.ptr<uint8_t>(j);
    uint8_t* d = out.ptr<uint8_t>(j);
    for (int i = 0; i + 1 < bgr.cols; i += 2) {
      const uint8_t* a = s + 3 * i;
      const uint8_t* b = a + 3;
      auto lim_y = [](double y) { return cv::saturate_cast<uint8_t>(16 + y * 219.0 / 255.0); };
      auto lim_c = [](double c) {
        return cv::saturate_cast<uint8_t>(128 + (c - 128) * 224.0 / 255.0);
      };
      d[2 * i] = lim_y(a[0]);
      d[2 * i + 1] = lim_c(0.5 * (a[2] + b[2]));  // U = Cb
      d[2 * i + 2] = lim_y(b[0]);
      d[2 * i + 3] = lim_c(0.5 * (a[1] + b[1]));  // V = Cr
    }
  }
  return out;
}

// Decodes `clip` and tracks every frame as `run` does (with its look back); scores against
// `truth` when given. `transform`, when set, edits each decoded BGR frame first (lighting
// changes).
inline TrackScore TrackClip(const std::filesystem::path& clip, const TrackerConfig& config,
                            const SynthTruth* truth, bool as_yuyv = false,
                            int max_frames = 1 << 30,
                            const std::function<void(int, cv::Mat*)>& transform = {}) {
  // Real clips (no truth) through the replay source: upright, on their container's clock.
  std::optional<VideoFileSource> source;
  cv::VideoCapture cap;
  if (truth) {
    if (!cap.open(clip.string(), cv::CAP_FFMPEG)) throw std::runtime_error("cannot open " + clip.string());
  } else {
    source.emplace(VideoFileSourceConfig{clip.string(), false});
  }
  Tracker tracker(config);
  LookBackTracker look_back(tracker);
  TrackScore s;
  auto keep = [&](std::vector<TrackedFrame> settled) {
    for (const TrackedFrame& f : settled) s.obs.push_back(f.obs);
  };
  for (int i = 0; i < max_frames; ++i) {
    cv::Mat img;
    int64_t utime = 0;
    if (source) {
      std::optional<Frame> next = source->Next();
      if (!next) break;
      img = next->image;
      utime = next->utime;
    } else {
      if (!cap.read(img)) break;
      utime = static_cast<int64_t>(std::llround(i / (truth ? truth->fps : 1) * 1e6));
    }
    if (transform) transform(i, &img);
    Frame f;
    f.image = as_yuyv ? BgrToYuyv(img) : img;
    f.owns_image = true;  // a new picture every frame
    f.format = as_yuyv ? PixelFormat::kYuyv : PixelFormat::kBgr24;
    f.index = i;
    f.sequence = i;
    f.utime = utime;
    keep(look_back.Track(f));
  }
  keep(look_back.Flush());
  std::vector<double> err;
  for (size_t i = 0; i < s.obs.size(); ++i) {
    const BallObservation& o = s.obs[i];
    if (o.found) ++s.found_total;
    if (!truth || i >= truth->frames.size()) continue;
    const SynthTruthFrame& t = truth->frames[i];
    const double e = std::hypot(o.cx - t.cx, o.cy - t.cy);
    if (o.found && e > std::max(3.0, truth->radius_px / 2)) ++s.wrong;
    if (!t.fully_in_view) continue;
    ++s.in_view;
    if (!o.found) {
      ++s.lost;
      continue;
    }
    err.push_back(e);
    s.mean_dx += o.cx - t.cx;
    s.mean_dy += o.cy - t.cy;
  }
  s.describe = tracker.Describe();
  s.color_nu = tracker.color().nu();
  s.color_nv = tracker.color().nv();
  if (!err.empty()) {
    double ss = 0;
    for (double e : err) ss += e * e;
    s.rms = std::sqrt(ss / static_cast<double>(err.size()));
    s.mean_dx /= static_cast<double>(err.size());
    s.mean_dy /= static_cast<double>(err.size());
    std::sort(err.begin(), err.end());
    s.p99 = err[std::min(err.size() - 1, static_cast<size_t>(0.99 * static_cast<double>(err.size())))];
    s.max = err.back();
  }
  return s;
}

inline TrackerConfig ConfigForColor(const double bgr[3], const std::string& name) {
  TrackerConfig c;
  c.has_color = true;
  for (int k = 0; k < 3; ++k) c.color_bgr[k] = bgr[k];
  c.color_name = name;
  return c;
}

}  // namespace bouncefit::testing
