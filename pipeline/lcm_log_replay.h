#pragma once
// LCM logs (the lcm-logger format) read strictly, and republished with their original
// pacing, scaled, so detect and fit can be rerun without video.
//
// The reader is our own, not lcm::LogFile: LCM 1.3.1's reader skips garbage silently while
// hunting for the next sync word and reports a truncated event as a clean end, so a corrupt
// log would replay as a shorter one. Here a corrupt log is an error that says where.
#include <atomic>
#include <cstdint>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "replay/pacer.h"

namespace bouncefit {

class LcmBus;

struct LcmLogEvent {
  int64_t eventnum = 0;
  int64_t utime = 0;  // when the logger received it, microseconds (wall clock)
  std::string channel;
  std::vector<uint8_t> data;
};

class LcmLogReader {
 public:
  // Throws std::runtime_error with a one-line reason if the file is missing or does not
  // start like an LCM log.
  explicit LcmLogReader(const std::string& path);
  // The next event, nullopt at the end. Throws std::runtime_error("corrupt LCM log ...: ...
  // at byte N (after K events)") for a broken header, an implausible length or a truncated
  // event; the events returned before stay valid.
  std::optional<LcmLogEvent> Next();
  int64_t events_read() const { return events_; }

 private:
  [[noreturn]] void Corrupt(const std::string& why, int64_t at) const;
  std::string path_;
  std::ifstream in_;
  int64_t size_ = 0;
  int64_t offset_ = 0;
  int64_t events_ = 0;
};

struct LogReplayConfig {
  double speed = 1.0;                  // 0: as fast as possible
  std::string channels_regex = ".*";   // whole-name match, as LCM subscriptions do
};

struct LogReplayStats {
  int64_t events = 0;      // events read from the log
  int64_t published = 0;   // events republished (channel matched)
  int64_t publish_failures = 0;
  int64_t first_utime = 0, last_utime = 0;  // of the published events
  double wall_s = 0;
  int64_t max_late_us = 0;
  double log_s() const { return (last_utime - first_utime) * 1e-6; }
};

using PublishFn = std::function<bool(const std::string& channel, const void* data, std::size_t size)>;
// Publishing on a bus.
PublishFn PublishOn(LcmBus& bus);

// Republishes the log's events through publish, each at its logged time relative to the
// first (scaled by 1/speed), until the end or *stop. Throws std::invalid_argument for a bad
// regex or speed, std::runtime_error for a missing or corrupt log (after publishing every
// event before the damage; *stats then says how many).
void ReplayLcmLog(const std::string& path, const LogReplayConfig& config,
                  const PublishFn& publish, LogReplayStats* stats,
                  const std::atomic<bool>* stop = nullptr,
                  PacerClock& clock = SteadyPacerClock());

}  // namespace bouncefit
