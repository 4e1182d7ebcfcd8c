#pragma once
// A live microphone read on its own thread: AlsaMicrophone's reads block a period at a
// time, the frame loop must not, so chunks wait here until the loop takes them.
#include <atomic>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "capture/alsa_microphone.h"

namespace bouncefit {

class MicrophoneReader {
 public:
  // Opens the device (throws std::runtime_error like AlsaMicrophone) and starts reading.
  explicit MicrophoneReader(AlsaMicrophoneConfig config);
  ~MicrophoneReader();  // stops reading and joins
  MicrophoneReader(const MicrophoneReader&) = delete;
  MicrophoneReader& operator=(const MicrophoneReader&) = delete;

  int sample_rate() const { return mic_.sample_rate(); }
  std::string Describe() const { return mic_.Describe(); }
  // The chunks read since the last call, oldest first (t0_s on CLOCK_MONOTONIC).
  std::vector<AudioChunk> Take();
  // Stops reading (the chunks already read stay to be taken).
  void Stop();
  // The device failed (unplugged): no more chunks will come.
  bool failed() const { return failed_; }
  int64_t overruns() const { return mic_.overruns(); }
  // Chunks dropped because nobody took them for this long (the loop stalled).
  int64_t dropped_chunks() const { return dropped_; }

 private:
  void Loop();

  AlsaMicrophone mic_;
  std::mutex mutex_;
  std::deque<AudioChunk> queue_;
  std::atomic<bool> stop_{false}, failed_{false};
  std::atomic<int64_t> dropped_{0};
  std::thread thread_;
};

}  // namespace bouncefit
