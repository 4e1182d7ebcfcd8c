#pragma once
// The built-in sample drop `run` replays when given no input: rendered once by synth and
// cached, so a first run needs no camera and no download.
#include <filesystem>
#include <functional>
#include <string>

namespace bouncefit::cli {

struct SampleClip {
  std::filesystem::path clip;   // the .avi
  std::filesystem::path truth;  // its synth truth file
  std::string ball;             // the preset it shows
};

// Renders the sample into the cache directory ($XDG_CACHE_HOME/bouncefit, else
// ~/.cache/bouncefit, else the system temp dir) unless already there. `say` gets one line
// when it has to render.
SampleClip BuiltInSample(const std::function<void(const std::string&)>& say);

}  // namespace bouncefit::cli
