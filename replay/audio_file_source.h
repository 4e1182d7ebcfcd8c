#pragma once
// The sound track of a video file (.mp4, .mov, .avi, ...) decoded with FFmpeg's libraries
// to mono float samples, with times in the video's clock: t = 0 is the first video frame,
// as replay/video_file_source.h gives it (the container's timestamps relate the two; the
// offset phones add between them is estimated later, from impacts both senses found).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "capture/audio_chunk.h"

namespace bouncefit {

class AudioFileSource {
 public:
  // Opens the file. Throws std::runtime_error with a one-line reason when the file is
  // missing or unreadable; a file without sound opens with has_audio() false.
  explicit AudioFileSource(const std::string& path);
  ~AudioFileSource();
  AudioFileSource(const AudioFileSource&) = delete;
  AudioFileSource& operator=(const AudioFileSource&) = delete;

  bool has_audio() const;
  int sample_rate() const;
  // "aac 44100 Hz stereo", for the run's banner.
  std::string Describe() const;

  // The next decoded stretch (a few ms to tens of ms; t0_s in the video's clock); false at
  // the end of the track.
  // Samples of consecutive chunks are contiguous unless the container leaves a gap.
  bool Next(AudioChunk* chunk);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The whole track in one chunk (gaps filled with silence, overlaps dropped). Returns an
// empty chunk (sample_rate 0) when the file has no sound. Throws like the constructor.
AudioChunk ReadAudioTrack(const std::string& path);

}  // namespace bouncefit
