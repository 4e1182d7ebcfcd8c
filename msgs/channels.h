#pragma once
// Channel names and the default bus URL, overridable from every node's flags.
#include <string>

namespace bouncefit {

// ttl=0 keeps traffic on this machine unless the user asks for a LAN.
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

struct Channels {
  std::string ball_box = "BALL_BOX";
  std::string calibration = "CALIBRATION";
  std::string bounce_peak = "BOUNCE_PEAK";
  std::string fit_update = "FIT_UPDATE";
  std::string impact = "IMPACT";
  std::string stream = "STREAM";  // the capture node's stream: start and end (stream_t)
  std::string drop = "DROP";      // the detect node's drop ended / stream done (drop_t)
};

}  // namespace bouncefit
