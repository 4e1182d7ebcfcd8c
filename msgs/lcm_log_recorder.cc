#include "msgs/lcm_log_recorder.h"

#include <stdexcept>

#include "msgs/lcm_bus.h"

namespace bouncefit {

LcmLogRecorder::LcmLogRecorder(const std::string& path, std::size_t max_queue)
    : path_(path), max_queue_(max_queue) {
  log_ = std::make_unique<lcm::LogFile>(path, "w");
  if (!log_->good()) throw std::runtime_error("cannot write LCM log '" + path + "'");
  writer_ = std::thread(&LcmLogRecorder::WriterLoop, this);
}

LcmLogRecorder::~LcmLogRecorder() { Close(); }

void LcmLogRecorder::Attach(LcmBus& bus) {
  bus.SubscribeRaw(".*", [this](const std::string& channel, const void* data, std::size_t size,
                                int64_t utime) { Record(channel, data, size, utime); });
}

void LcmLogRecorder::Record(const std::string& channel, const void* data, std::size_t size,
                            int64_t utime) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (closing_ || queue_.size() >= max_queue_) {
    ++dropped_;
    return;
  }
  const auto* bytes = static_cast<const uint8_t*>(data);
  queue_.push_back(Entry{channel, std::vector<uint8_t>(bytes, bytes + size), utime});
  cv_.notify_one();
}

void LcmLogRecorder::WriterLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return closing_ || !queue_.empty(); });
    while (!queue_.empty()) {
      Entry e = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      lcm::LogEvent ev;
      ev.eventnum = 0;  // lcm assigns event numbers on write
      ev.timestamp = e.utime;
      ev.channel = e.channel;
      ev.datalen = static_cast<int32_t>(e.data.size());
      ev.data = e.data.data();
      const bool ok = log_->writeEvent(&ev) == 0;
      lock.lock();
      if (ok) ++written_; else ++dropped_;
    }
    if (closing_) return;
  }
}

void LcmLogRecorder::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closing_) return;
    closing_ = true;
    cv_.notify_one();
  }
  writer_.join();
  log_.reset();
}

int64_t LcmLogRecorder::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}

int64_t LcmLogRecorder::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

}  // namespace bouncefit
