// Tracker speed. Renders a 640x480 synth clip (or takes --clip), then measures in one run:
//   1. tracking alone on frames already in memory (BGR and YUYV), frames/s on one core;
//   2. decode alone vs decode + track over the same file, in N pairs (each pass laps a short
//      clip to last --min-pass-s), the median of the pairs' ratios;
//   3. decode alone beside busy cores (arithmetic at idle priority): the machine's own floor
//      for that ratio with any tracker that keeps a core busy;
// and prints the ratios against the targets (>= 2000 frames/s; decode+track <= 1.2x decode).
// Files are read as `run` reads them (replay/video_file_source: upright, container times);
// a --clip is tracked with the automatic choice (no colour given), as a new user runs it.
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/videoio.hpp>

#include <sched.h>
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "capture/frame_memory.h"
#include "replay/video_file_source.h"
#include "synth/synth_clip.h"
#include "tests/tracker_test_util.h"
#include "track/look_back_tracker.h"
#include "track/tracker.h"

namespace {

using bouncefit::Frame;
using bouncefit::PixelFormat;
using bouncefit::LookBackTracker;
using bouncefit::Tracker;
using bouncefit::TrackerConfig;
using Clock = std::chrono::steady_clock;

// The machine is shared: CPU time of this process (all its threads, FFmpeg's included) is
// what a frame costs; wall time is printed beside it. CLOCK_THREAD_CPUTIME_ID: this thread's.
double CpuNow(clockid_t clock = CLOCK_PROCESS_CPUTIME_ID) {
  timespec ts;
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Page faults: a buffer freed to the system and allocated again each frame faults in every
// page of it again (1729 a frame on the 1034x864 clip, decoding slowed by half).
long MinorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

struct Timer {
  Clock::time_point wall0 = Clock::now();
  double cpu0 = CpuNow();
  long faults0 = MinorFaults();
  double wall = 0, cpu = 0;
  long faults = 0;
  void Stop() {
    wall = std::chrono::duration<double>(Clock::now() - wall0).count();
    cpu = CpuNow() - cpu0;
    faults = MinorFaults() - faults0;
  }
};

struct Best {
  double wall = 1e30, cpu = 1e30;
  long faults = 0;
  void Take(const Timer& t) {
    wall = std::min(wall, t.wall);
    if (t.cpu < cpu) faults = t.faults;
    cpu = std::min(cpu, t.cpu);
  }
};

// Decodes the clip `laps` times over (a short clip's single pass lasts tens of ms, less than
// the noise of a shared machine); with a tracker config, tracks each frame too, a fresh
// tracker each lap as a fresh run. Frames in *n (per lap); the tracking's own CPU time (this
// thread's, inside the loop) in *track_cpu; the time this thread waited for frames and the
// reading thread for room, per lap, in *waits.
Timer DecodePass(const bouncefit::VideoFileSourceConfig& config, const TrackerConfig* tracking,
                 int laps, int* n, int* found, double* track_cpu = nullptr,
                 bouncefit::VideoFileSource::QueueWaits* waits = nullptr) {
  double in_track = 0;
  bouncefit::VideoFileSource::QueueWaits waited;
  Timer t;
  for (int lap = 0; lap < laps; ++lap) {
    bouncefit::VideoFileSource source(config);
    std::optional<Tracker> tracker;
    std::optional<LookBackTracker> look_back;  // as `run` tracks
    if (tracking) tracker.emplace(*tracking), look_back.emplace(*tracker);
    *n = 0;
    *found = 0;
    while (std::optional<Frame> f = source.Next()) {
      if (look_back) {
        const double c0 = CpuNow(CLOCK_THREAD_CPUTIME_ID);
        for (const auto& settled : look_back->Track(*f)) *found += settled.obs.found;
        in_track += CpuNow(CLOCK_THREAD_CPUTIME_ID) - c0;
      }
      ++*n;
    }
    if (look_back)
      for (const auto& settled : look_back->Flush()) *found += settled.obs.found;
    const bouncefit::VideoFileSource::QueueWaits lap_waits = source.queue_waits();
    waited.consumer_s += lap_waits.consumer_s;
    waited.reader_s += lap_waits.reader_s;
  }
  if (track_cpu) *track_cpu = in_track / laps;
  if (waits) *waits = {waited.consumer_s / laps, waited.reader_s / laps};
  t.Stop();
  t.wall /= laps, t.cpu /= laps;
  t.faults /= laps;
  return t;
}

// Keeps every core but one busy with arithmetic at the lowest priority (SCHED_IDLE: it runs
// only where nothing else would), touching no memory: what any tracker that kept a core busy
// would at least cost a decoder that spreads over the cores, without its own work or caches.
class BusyCores {
 public:
  BusyCores() {
    const unsigned n = std::max(2u, std::thread::hardware_concurrency()) - 1;
    for (unsigned i = 0; i < n; ++i)
      threads_.emplace_back([this] {
        sched_param none{};
        sched_setscheduler(0, SCHED_IDLE, &none);  // this thread only
        double x = 1;
        while (!stop_.load(std::memory_order_relaxed))
          for (int k = 0; k < 10000; ++k) x = x * 1.0000001 + 1e-9;
        sink_ = x;
      });
  }
  ~BusyCores() {
    stop_ = true;
    for (std::thread& t : threads_) t.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
  volatile double sink_ = 0;
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Tracks frames already in memory, as the source gave them (a file's frames keep the
// decoder's own luma, which the tracker reads in `run`).
Timer TrackPass(const std::vector<Frame>& frames, const TrackerConfig& config, int* found) {
  Tracker tracker(config);
  LookBackTracker look_back(tracker);
  *found = 0;
  Timer t;
  for (const Frame& f : frames)
    for (const auto& settled : look_back.Track(f)) *found += settled.obs.found;
  for (const auto& settled : look_back.Flush()) *found += settled.obs.found;
  t.Stop();
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string clip, ball = "pingpong";
    int repeats = 3;
    bool system_allocator = false;
    int read_ahead = -1, decoder_threads = -1;
    double min_pass_s = 0.3;
    bool track_once = false;
    bool ball_only = false;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--clip" && i + 1 < argc) clip = argv[++i];
      else if (a == "--ball" && i + 1 < argc) ball = argv[++i];
      else if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
      else if (a == "--freeing-allocator") system_allocator = true;
      else if (a == "--read-ahead" && i + 1 < argc) read_ahead = std::max(0, std::atoi(argv[++i]));
      else if (a == "--decoder-threads" && i + 1 < argc) decoder_threads = std::max(0, std::atoi(argv[++i]));
      else if (a == "--min-pass-s" && i + 1 < argc) min_pass_s = std::max(0.0, std::atof(argv[++i]));
      else if (a == "--track-once") track_once = true;
      else if (a == "--ball-only") ball_only = true;
      else {
        const bool help = a == "--help" || a == "-h";
        std::fprintf(help ? stdout : stderr, "usage: track_bench [--ball NAME] [--clip FILE.avi] [--repeats N] [--freeing-allocator]\n"
                             "                   [--read-ahead FRAMES] [--decoder-threads N]  (default: as run reads a file)\n"
                             "                   [--min-pass-s S]  (a decode pass laps a short clip to last S seconds; 0.3)\n"
                             "                   [--track-once]  (decode, track the frames once, stop: for a profiler)\n"
                             "                   [--ball-only]  (no camera following, no reviews of a still lock: what\n"
                             "                                   the ratio is when only the ball itself is tracked)\n");
        return help ? 0 : 2;
      }
    }
    cv::setNumThreads(1);  // one core for OpenCV's own loops (blur, labelling)
    // As `bouncefit` does; --freeing-allocator measures without it (glibc's defaults).
    if (!system_allocator) bouncefit::KeepFreedFrameMemory();
    const auto preset = bouncefit::ResolveBallPreset(ball);
    TrackerConfig config = bouncefit::testing::ConfigForColor(preset.color_bgr, ball);
    if (!clip.empty()) config = TrackerConfig{};  // automatic choice, as `run CLIP` does
    if (ball_only) {
      // A lower bound on what any tracker of ours could cost: the camera's motion and the
      // search for a better candidate than a still lock left out (the choice, the ball's
      // window and its rim fit stay).
      config.follow_camera = false;
      config.auto_review_s = 1e9;
    }
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
    std::vector<Frame> bgr, yuyv;
    {
      bouncefit::VideoFileSource source({clip, false});
      for (int64_t i = 0; std::optional<Frame> f = source.Next(); ++i) {
        Frame kept = *f;  // the decoder's luma with it
        kept.image = f->image.clone();
        kept.owns_image = true;  // never written again, as a file's frames
        kept.index = i;
        Frame packed = kept;
        packed.image = bouncefit::testing::BgrToYuyv(f->image);
        packed.format = PixelFormat::kYuyv;
        packed.luma = cv::Mat(), packed.luma_owner.reset();  // a camera's frames have none
        bgr.push_back(std::move(kept));
        yuyv.push_back(std::move(packed));
      }
    }
    if (bgr.empty()) throw std::runtime_error("no frames in " + clip);
    std::printf("clip %s: %zu frames %dx%d, %s\n", clip.c_str(), bgr.size(), bgr[0].image.cols,
                bgr[0].image.rows, config.has_color ? ("ball colour of " + ball).c_str() : "automatic choice");
    if (track_once) {
      // For a profiler: the clip tracked once, nothing else timed (valgrind --tool=callgrind
      // --toggle-collect='bouncefit::Tracker::Track*' counts tracking's instructions alone).
      int found = 0;
      const Timer t = TrackPass(bgr, config, &found);
      std::printf("tracked once: found in %d of %zu frames, %.1f us/frame CPU\n", found, bgr.size(),
                  1e6 * t.cpu / static_cast<double>(bgr.size()));
      return 0;
    }

    // As `run` reads the file (ahead, on a thread of its own), unless told otherwise; and the
    // file decoded in Next() with the decoder's own threads, the fastest decoding alone.
    bouncefit::VideoFileSourceConfig as_run = bouncefit::ReadAheadConfig(clip);
    if (read_ahead >= 0) as_run.read_ahead = read_ahead;
    if (decoder_threads >= 0) as_run.decoder_threads = decoder_threads;
    const bouncefit::VideoFileSourceConfig plain{clip, false};
    Best t_bgr, t_yuyv, t_dec, t_both, t_plain;
    int found_bgr = 0, found_yuyv = 0, n_dec = 0, n_both = 0, f0 = 0, found_both = 0;
    // Laps enough for a decode pass of min_pass_s.
    const double one_lap_s = DecodePass(as_run, nullptr, 1, &n_dec, &f0).wall;
    const int laps = std::clamp(static_cast<int>(std::ceil(min_pass_s / std::max(one_lap_s, 1e-4))), 1, 1000);
    std::printf("decode passes of %d lap(s) of the clip (one lap %.3f s, at least %.2f s a pass)\n",
                laps, one_lap_s, min_pass_s);
    std::vector<double> pair_wall, pair_cpu, busy_wall;
    for (int r = 0; r < repeats; ++r) {
      t_bgr.Take(TrackPass(bgr, config, &found_bgr));
      t_yuyv.Take(TrackPass(yuyv, config, &found_yuyv));
      t_plain.Take(DecodePass(plain, nullptr, laps, &n_dec, &f0));
      // Decode alone and decode + track one after the other: each pair's ratio has seen the
      // same load on the machine.
      const Timer dec = DecodePass(as_run, nullptr, laps, &n_dec, &f0);
      double track_cpu = 0;
      bouncefit::VideoFileSource::QueueWaits waits;
      const Timer both = DecodePass(as_run, &config, laps, &n_both, &found_both, &track_cpu, &waits);
      {
        // Decode alone again beside busy cores, against the same pair's decode alone.
        const BusyCores busy;
        busy_wall.push_back(DecodePass(as_run, nullptr, laps, &n_dec, &f0).wall / dec.wall);
      }
      t_dec.Take(dec);
      t_both.Take(both);
      pair_wall.push_back(both.wall / dec.wall);
      pair_cpu.push_back(both.cpu / dec.cpu);
      const double per_frame = 1e6 / std::max(n_both, 1);
      std::printf("pass %d: decode+track / decode alone %.3f wall, %.3f CPU; tracking within it %.1f us/frame CPU;"
                  " waiting: tracking for frames %.1f, reading for room %.1f us/frame (wall %.1f)\n",
                  r, pair_wall.back(), pair_cpu.back(), track_cpu * per_frame, waits.consumer_s * per_frame,
                  waits.reader_s * per_frame, both.wall * per_frame);
    }
    // (Re)acquisition: a fresh tracker on every frame searches the whole frame each time.
    Best t_acq;
    int found_acq = 0;
    const size_t acq_frames = std::min<size_t>(bgr.size(), 120);
    for (int r = 0; r < repeats; ++r) {
      Timer t;
      found_acq = 0;
      for (size_t i = 0; i < acq_frames; ++i) {
        Tracker fresh(config);
        found_acq += fresh.Track(bgr[i]).found;
      }
      t.Stop();
      t_acq.Take(t);
    }
    const double n = static_cast<double>(bgr.size());
    auto line = [&](const char* what, const Best& b, int found) {
      std::printf("%-22s %8.0f frames/s CPU (%6.1f us/frame), %8.0f frames/s wall, found %d/%zu"
                  " -> %.2fx the 2000 fps target\n",
                  what, n / b.cpu, 1e6 * b.cpu / n, n / b.wall, found, bgr.size(),
                  n / b.cpu / 2000);
    };
    line("tracking alone, BGR", t_bgr, found_bgr);
    line("tracking alone, YUYV", t_yuyv, found_yuyv);
    std::printf("%-22s %8.0f frames/s CPU (%6.1f us/frame), found %d/%zu\n",
                "full-frame search", acq_frames / t_acq.cpu, 1e6 * t_acq.cpu / acq_frames,
                found_acq, acq_frames);
    std::printf("reading as run does: %d frames ahead, %d decoder threads (0: one per core)\n",
                as_run.read_ahead, as_run.decoder_threads);
    std::printf("%-22s %8.0f frames/s CPU, %8.0f frames/s wall (%d frames), %.0f page faults/frame\n",
                "decode alone", n_dec / t_dec.cpu, n_dec / t_dec.wall, n_dec,
                static_cast<double>(t_dec.faults) / n_dec);
    std::printf("%-22s %8.0f frames/s CPU, %8.0f frames/s wall\n", "decode alone, plain",
                n_dec / t_plain.cpu, n_dec / t_plain.wall);
    std::printf("%-22s %8.0f frames/s CPU, %8.0f frames/s wall (%d frames, found %d), %.0f page faults/frame\n",
                "decode + track", n_both / t_both.cpu, n_both / t_both.wall, n_both, found_both,
                static_cast<double>(t_both.faults) / n_both);
    std::printf("decode+track / decode alone, best of each: %.3f CPU time, %.3f wall time\n",
                t_both.cpu / t_dec.cpu, t_both.wall / t_dec.wall);
    std::printf("decode+track / decode alone: %.3f CPU time, %.3f wall time, median of %d pairs (target <= 1.2)\n",
                Median(pair_cpu), Median(pair_wall), repeats);
    std::printf("decode alone beside busy cores (idle-priority arithmetic) / decode alone: %.3f wall time,"
                " median of %d: the least any tracker that keeps a core busy would cost here\n",
                Median(busy_wall), repeats);
    std::printf("decode+track / decode alone, plain (in Next(), the decoder's own threads): %.3f wall time\n",
                t_both.wall / t_plain.wall);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "track_bench: error: %s\n", e.what());
    return 1;
  }
}
