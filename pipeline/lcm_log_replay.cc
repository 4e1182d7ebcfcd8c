#include "pipeline/lcm_log_replay.h"

#include <chrono>
#include <filesystem>
#include <regex>
#include <stdexcept>

#include "msgs/lcm_bus.h"

namespace bouncefit {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01;   // every event starts with it (big-endian)
constexpr int64_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
constexpr int32_t kMaxChannel = 256;
constexpr int32_t kMaxData = 1 << 28;        // 256 MiB: larger is a broken length field

uint64_t BigEndian(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

LcmLogReader::LcmLogReader(const std::string& path) : path_(path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw std::runtime_error("cannot open LCM log '" + path + "': no such file");
  if (std::filesystem::is_directory(path, ec))
    throw std::runtime_error("cannot open LCM log '" + path + "': it is a directory");
  in_.open(path, std::ios::binary);
  if (!in_) throw std::runtime_error("cannot open LCM log '" + path + "': cannot read it");
  size_ = static_cast<int64_t>(std::filesystem::file_size(path, ec));
  if (size_ == 0) return;  // an empty log: no events
  uint8_t sync[4] = {};
  in_.read(reinterpret_cast<char*>(sync), 4);
  if (in_.gcount() < 4 || BigEndian(sync, 4) != kSyncWord)
    throw std::runtime_error("'" + path + "' is not an LCM log (no event header at its start)");
  in_.seekg(0);
}

void LcmLogReader::Corrupt(const std::string& why, int64_t at) const {
  throw std::runtime_error("corrupt LCM log '" + path_ + "': " + why + " at byte " +
                           std::to_string(at) + " (after " + std::to_string(events_) +
                           " events)");
}

std::optional<LcmLogEvent> LcmLogReader::Next() {
  if (offset_ >= size_) return std::nullopt;
  const int64_t start = offset_;
  if (size_ - offset_ < kHeaderBytes) Corrupt("truncated event header", start);
  uint8_t h[kHeaderBytes];
  in_.read(reinterpret_cast<char*>(h), kHeaderBytes);
  if (in_.gcount() != kHeaderBytes) Corrupt("read failed", start);
  if (BigEndian(h, 4) != kSyncWord) Corrupt("no event header (bad sync word)", start);
  LcmLogEvent e;
  e.eventnum = static_cast<int64_t>(BigEndian(h + 4, 8));
  e.utime = static_cast<int64_t>(BigEndian(h + 12, 8));
  const auto channel_len = static_cast<int32_t>(BigEndian(h + 20, 4));
  const auto data_len = static_cast<int32_t>(BigEndian(h + 24, 4));
  if (channel_len <= 0 || channel_len > kMaxChannel)
    Corrupt("implausible channel length " + std::to_string(channel_len), start);
  if (data_len < 0 || data_len > kMaxData)
    Corrupt("implausible data length " + std::to_string(data_len), start);
  if (size_ - offset_ - kHeaderBytes < int64_t(channel_len) + data_len)
    Corrupt("truncated event (" + std::to_string(channel_len + data_len) + " bytes announced, " +
                std::to_string(size_ - offset_ - kHeaderBytes) + " left)",
            start);
  e.channel.resize(static_cast<std::size_t>(channel_len));
  in_.read(e.channel.data(), channel_len);
  e.data.resize(static_cast<std::size_t>(data_len));
  in_.read(reinterpret_cast<char*>(e.data.data()), data_len);
  if (!in_) Corrupt("read failed", start);
  for (unsigned char c : e.channel)
    if (c < 32 || c >= 127) Corrupt("channel name is not printable", start);
  offset_ += kHeaderBytes + channel_len + data_len;
  ++events_;
  return e;
}

PublishFn PublishOn(LcmBus& bus) {
  return [&bus](const std::string& channel, const void* data, std::size_t size) {
    return bus.raw().publish(channel, data, static_cast<unsigned int>(size)) == 0;
  };
}

void ReplayLcmLog(const std::string& path, const LogReplayConfig& config,
                  const PublishFn& publish, LogReplayStats* stats,
                  const std::atomic<bool>* stop, PacerClock& clock) {
  std::regex filter;
  try {
    filter = std::regex(config.channels_regex, std::regex::ECMAScript);
  } catch (const std::regex_error&) {
    throw std::invalid_argument("--channels is not a valid regular expression: '" +
                                config.channels_regex + "'");
  }
  Pacer pacer(config.speed, clock);
  LcmLogReader reader(path);
  *stats = LogReplayStats{};
  const int64_t wall0 = clock.NowMicros();
  struct WallTime {
    PacerClock& clock;
    int64_t wall0;
    LogReplayStats* stats;
    ~WallTime() { stats->wall_s = (clock.NowMicros() - wall0) * 1e-6; }
  } wall{clock, wall0, stats};
  while (!(stop && stop->load())) {
    auto e = reader.Next();
    if (!e) break;
    ++stats->events;
    if (!std::regex_match(e->channel, filter)) continue;
    const int64_t late = pacer.WaitFor(e->utime);
    if (late > stats->max_late_us) stats->max_late_us = late;
    if (publish(e->channel, e->data.data(), e->data.size())) {
      if (stats->published == 0) stats->first_utime = e->utime;
      stats->last_utime = e->utime;
      ++stats->published;
    } else {
      ++stats->publish_failures;
    }
  }
}

}  // namespace bouncefit
