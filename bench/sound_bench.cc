// Sound cost against the video path, per clip (the target: decoding and detecting the sound
// costs <= 10% of the video path). For each clip given, in one
// run and alternated, best of 3 each:
//   video path: decode every frame (replay/video_file_source) and track it (automatic tracker);
//   sound path: decode the track chunk by chunk (replay/audio_file_source) and detect its
//   impacts as run does (detect_s: the detector's share of it).
// Prints CPU seconds of this process (FFmpeg's threads included) and the ratio sound / video.
//   sound_bench CLIP...
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "detect/impact_detector.h"
#include "replay/audio_file_source.h"
#include "replay/video_file_source.h"
#include "track/tracker.h"

namespace {

double CpuNow() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double VideoPath(const std::string& clip, int* frames) {
  const double t0 = CpuNow();
  bouncefit::VideoFileSource source({clip, false});
  bouncefit::Tracker tracker(bouncefit::TrackerConfig{});
  *frames = 0;
  while (auto f = source.Next()) {
    tracker.Track(*f);
    ++*frames;
  }
  return CpuNow() - t0;
}

// Decodes chunk by chunk and detects as run does; *detect_s: the detector's share.
double SoundPath(const std::string& clip, int* impacts, double* seconds, double* detect_s) {
  const double t0 = CpuNow();
  bouncefit::AudioFileSource source(clip);
  *impacts = 0;
  *seconds = 0;
  *detect_s = 0;
  if (source.has_audio()) {
    bouncefit::ImpactDetector detector({}, source.sample_rate());
    bouncefit::AudioChunk chunk;
    while (source.Next(&chunk)) {
      const double d0 = CpuNow();
      *impacts += static_cast<int>(detector.Push(chunk.t0_s, chunk.samples.data(), chunk.samples.size()).size());
      *detect_s += CpuNow() - d0;
      *seconds += static_cast<double>(chunk.samples.size()) / chunk.sample_rate;
    }
    *impacts += static_cast<int>(detector.Finish().size());
  }
  return CpuNow() - t0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> clips(argv + 1, argv + argc);
  if (clips.empty() || clips[0] == "--help") {
    std::fprintf(stderr, "usage: sound_bench CLIP...   (e.g. ../shared/real-clips/*.mp4 *.mov *.avi)\n");
    return clips.empty() ? 1 : 0;
  }
  std::printf("%-42s %7s %9s %9s %9s %8s %8s %7s\n", "clip", "frames", "video_s", "sound_s",
              "detect_s", "audio_s", "impacts", "ratio");
  double total_video = 0, total_sound = 0;
  for (const auto& clip : clips) {
    try {
      double video = 1e30, sound = 1e30, seconds = 0, detect = 1e30;
      int frames = 0, impacts = 0;
      for (int pass = 0; pass < 3; ++pass) {
        video = std::min(video, VideoPath(clip, &frames));
        double d = 0;
        const double s = SoundPath(clip, &impacts, &seconds, &d);
        if (s < sound) sound = s, detect = d;
      }
      total_video += video;
      total_sound += sound;
      std::printf("%-42s %7d %8.3fs %8.3fs %8.3fs %7.2fs %8d %6.1f%%\n",
                  std::filesystem::path(clip).filename().c_str(), frames, video, sound, detect, seconds,
                  impacts, 100 * sound / video);
      std::fflush(stdout);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sound_bench: %s: %s\n", clip.c_str(), e.what());
      return 1;
    }
  }
  std::printf("all clips: sound %.3f s CPU = %.1f%% of the video path's %.3f s (target <= 10%%)\n",
              total_sound, 100 * total_sound / total_video, total_video);
  return 0;
}
