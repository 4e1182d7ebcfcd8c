#include "model/exported_sources.h"

#include <sstream>

namespace bouncefit {

std::vector<std::string> SoftBallWorldFileNames() {
  std::vector<std::string> names;
  std::stringstream list(BOUNCEFIT_SOFT_BALL_WORLD_FILES);  // set by model/CMakeLists.txt
  for (std::string name; std::getline(list, name, ',');) names.push_back(name);
  return names;
}

}  // namespace bouncefit
