#pragma once
// The soft ball's world as source text (model/soft_ball_world.h and the files it includes,
// listed in model/CMakeLists.txt), built into the library so that `fit --export` ships the
// very files the model was compiled from.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bouncefit {

// Their names (no folder; they live under model/), in the order CMake lists them.
std::vector<std::string> SoftBallWorldFileNames();
// The text of one of them, or nullopt for another name.
std::optional<std::string_view> EmbeddedSoftBallWorldFile(std::string_view file_name);

}  // namespace bouncefit
