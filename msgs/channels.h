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
};

}  // namespace bouncefit
