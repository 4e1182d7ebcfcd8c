#include "capture/microphone_reader.h"

#include <utility>

namespace bouncefit {
namespace {

// Chunks kept for a loop that stopped taking them: 10 s of 10 ms periods.
constexpr size_t kMaxQueued = 1000;

}  // namespace

MicrophoneReader::MicrophoneReader(AlsaMicrophoneConfig config)
    : mic_(std::move(config)), thread_([this] { Loop(); }) {}

MicrophoneReader::~MicrophoneReader() { Stop(); }

void MicrophoneReader::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void MicrophoneReader::Loop() {
  AudioChunk chunk;
  while (!stop_) {
    if (!mic_.Next(&chunk)) {
      failed_ = true;
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(chunk);
    if (queue_.size() > kMaxQueued) {
      queue_.pop_front();
      ++dropped_;
    }
  }
}

std::vector<AudioChunk> MicrophoneReader::Take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<AudioChunk> out(std::make_move_iterator(queue_.begin()),
                              std::make_move_iterator(queue_.end()));
  queue_.clear();
  return out;
}

}  // namespace bouncefit
