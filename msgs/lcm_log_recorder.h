#pragma once
// Records every message seen on a bus into an LCM log file (readable by lcm-logplayer).
//
// As lcm-logger does: the LCM handler only copies and queues; a thread of its own writes.
// If the writer falls behind by more than max_queue messages, new ones are dropped and
// counted rather than stalling the bus.
#include <lcm/lcm-cpp.hpp>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace bouncefit {

class LcmBus;

class LcmLogRecorder {
 public:
  // Opens (truncates) the log. Throws std::runtime_error if it cannot be written.
  LcmLogRecorder(const std::string& path, std::size_t max_queue = 100000);
  ~LcmLogRecorder();  // flushes everything queued and closes the file
  LcmLogRecorder(const LcmLogRecorder&) = delete;
  LcmLogRecorder& operator=(const LcmLogRecorder&) = delete;

  // Records every message the bus receives from now on.
  void Attach(LcmBus& bus);
  // Records one message directly (for messages a process publishes on a bus that does not
  // loop them back to itself).
  void Record(const std::string& channel, const void* data, std::size_t size, int64_t utime);
  // Writes what is queued and closes the file; later Records are dropped.
  void Close();

  int64_t written() const;
  int64_t dropped() const;

 private:
  struct Entry {
    std::string channel;
    std::vector<uint8_t> data;
    int64_t utime;
  };
  void WriterLoop();

  std::string path_;
  std::size_t max_queue_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Entry> queue_;
  bool closing_ = false;
  int64_t written_ = 0;
  int64_t dropped_ = 0;
  std::unique_ptr<lcm::LogFile> log_;
  std::thread writer_;
};

}  // namespace bouncefit
