#include "cli/sample_clip.h"

#include <cstdlib>
#include <system_error>

#include "synth/synth_clip.h"

namespace bouncefit::cli {
namespace {

std::filesystem::path CacheDir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::filesystem::path(xdg) / "bouncefit";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".cache" / "bouncefit";
  return std::filesystem::temp_directory_path() / "bouncefit-cache";
}

}  // namespace

SampleClip BuiltInSample(const std::function<void(const std::string&)>& say) {
  // Bump the version whenever the config below or the renderer changes what it draws.
  const std::string name = "sample-v1-pingpong-1m";
  SampleClip sample;
  sample.ball = "pingpong";
  const auto dir = CacheDir();
  sample.clip = dir / (name + ".avi");
  sample.truth = dir / (name + ".truth.json");
  if (std::filesystem::exists(sample.clip) && std::filesystem::exists(sample.truth)) return sample;

  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create cache directory '" + dir.string() + "'");
  SynthClipConfig config;
  config.ball = *FindBallPreset(sample.ball);
  config.drop_height_m = 1.0;
  config.duration_s = 5.0;
  config.noise_sigma = 2.0;
  config.roll_deg = 0.5;
  config.seed = 2026;
  // Render under a temporary name, then rename: an interrupted render leaves no half clip.
  const auto tmp = dir / (name + ".tmp.avi");
  config.out = tmp;
  say("rendering the built-in sample drop (once) into " + sample.clip.string());
  const SynthClipResult result = RenderSynthClip(config);
  std::filesystem::rename(result.truth_path, sample.truth);
  std::filesystem::rename(result.clip_path, sample.clip);
  return sample;
}

}  // namespace bouncefit::cli
