// Tracker speed. Renders a 640x480 synth clip (or takes --clip), then measures in one run:
//   1. tracking alone on frames already in memory (BGR and YUYV), frames/s on one core;
//   2. decode alone vs decode + track over the same file, alternated, best of N each;
// and prints the ratios against the targets (>= 2000 frames/s; decode+track <= 1.2x decode).
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "replay/synth_clip.h"
#include "tests/tracker_test_util.h"
#include "track/tracker.h"

namespace {

using bouncefit::Frame;
using bouncefit::PixelFormat;
using bouncefit::Tracker;
using bouncefit::TrackerConfig;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// Decodes the clip; with a tracker, tracks each frame too. Returns seconds, frames in *n.
double DecodePass(const std::string& clip, Tracker* tracker, int* n, int* found) {
  cv::VideoCapture cap(clip, cv::CAP_FFMPEG);
  if (!cap.isOpened()) throw std::runtime_error("cannot open " + clip);
  cv::Mat img;
  *n = 0;
  *found = 0;
  const auto t0 = Clock::now();
  while (cap.read(img)) {
    if (tracker) {
      Frame f;
      f.image = img;
      f.index = *n;
      f.utime = static_cast<int64_t>(*n) * 1000000 / 120;
      *found += tracker->Track(f).found;
    }
    ++*n;
  }
  return Seconds(t0, Clock::now());
}

double TrackPass(const std::vector<cv::Mat>& frames, PixelFormat format,
                 const TrackerConfig& config, int* found) {
  Tracker tracker(config);
  *found = 0;
  const auto t0 = Clock::now();
  for (size_t i = 0; i < frames.size(); ++i) {
    Frame f;
    f.image = frames[i];
    f.format = format;
    f.index = static_cast<int64_t>(i);
    f.utime = static_cast<int64_t>(i) * 1000000 / 120;
    *found += tracker.Track(f).found;
  }
  return Seconds(t0, Clock::now());
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string clip, ball = "pingpong";
    int repeats = 3;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--clip" && i + 1 < argc) clip = argv[++i];
      else if (a == "--ball" && i + 1 < argc) ball = argv[++i];
      else if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
      else {
        std::fprintf(stderr, "usage: track_bench [--ball NAME] [--clip FILE.avi] [--repeats N]\n");
        return 2;
      }
    }
    cv::setNumThreads(1);  // one core for OpenCV's own loops (blur, labelling)
    const auto preset = bouncefit::ResolveBallPreset(ball);
    TrackerConfig config = bouncefit::testing::ConfigForColor(preset.color_bgr, ball);
    if (clip.empty()) {
      bouncefit::SynthClipConfig sc;
      sc.ball = preset;
      sc.noise_sigma = 3;
      sc.roll_deg = 1;
      sc.duration_s = 4;
      sc.out = std::filesystem::temp_directory_path() / ("track_bench_" + ball + ".avi");
      bouncefit::RenderSynthClip(sc);
      clip = sc.out.string();
    }
    std::vector<cv::Mat> bgr, yuyv;
    {
      cv::VideoCapture cap(clip, cv::CAP_FFMPEG);
      cv::Mat img;
      while (cap.read(img)) {
        bgr.push_back(img.clone());
        yuyv.push_back(bouncefit::testing::BgrToYuyv(img));
      }
    }
    if (bgr.empty()) throw std::runtime_error("no frames in " + clip);
    std::printf("clip %s: %zu frames %dx%d, ball %s\n", clip.c_str(), bgr.size(), bgr[0].cols,
                bgr[0].rows, ball.c_str());

    double t_bgr = 1e9, t_yuyv = 1e9, t_dec = 1e9, t_both = 1e9;
    int found_bgr = 0, found_yuyv = 0, n_dec = 0, n_both = 0, f0 = 0, found_both = 0;
    for (int r = 0; r < repeats; ++r) {
      t_bgr = std::min(t_bgr, TrackPass(bgr, PixelFormat::kBgr24, config, &found_bgr));
      t_yuyv = std::min(t_yuyv, TrackPass(yuyv, PixelFormat::kYuyv, config, &found_yuyv));
      t_dec = std::min(t_dec, DecodePass(clip, nullptr, &n_dec, &f0));
      Tracker tracker(config);
      t_both = std::min(t_both, DecodePass(clip, &tracker, &n_both, &found_both));
    }
    const double n = static_cast<double>(bgr.size());
    const double fps_bgr = n / t_bgr, fps_yuyv = n / t_yuyv;
    std::printf("tracking alone, BGR : %8.0f frames/s (%.1f us/frame), found %d/%zu  -> %.2fx the 2000 fps target\n",
                fps_bgr, 1e6 / fps_bgr, found_bgr, bgr.size(), fps_bgr / 2000);
    std::printf("tracking alone, YUYV: %8.0f frames/s (%.1f us/frame), found %d/%zu  -> %.2fx the 2000 fps target\n",
                fps_yuyv, 1e6 / fps_yuyv, found_yuyv, yuyv.size(), fps_yuyv / 2000);
    std::printf("decode alone        : %8.0f frames/s (%d frames)\n", n_dec / t_dec, n_dec);
    std::printf("decode + track      : %8.0f frames/s (%d frames, found %d)\n", n_both / t_both,
                n_both, found_both);
    std::printf("decode+track / decode alone time ratio: %.3f (target <= 1.2)\n", t_both / t_dec);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "track_bench: error: %s\n", e.what());
    return 1;
  }
}
