#include "cli/scale_flags.h"

#include "cli/number_checks.h"

namespace bouncefit::cli {

void AddScaleFlags(CLI::App* cmd, ScaleFlags* flags) {
  const std::string group = "Scale";
  auto* px_per_m = cmd->add_option("--px-per-m", flags->px_per_m, "image scale, px/m (default: from the free fall)")
                       ->check(Positive())
                       ->group(group);
  // CLI11 says it at parse time; the rule itself is CalibratorConfig::IsValid's.
  cmd->add_option("--drop-height", flags->drop_height_m, "release height of the ball bottom, m (sets the scale)")
      ->check(Positive())
      ->excludes(px_per_m)
      ->group(group);
  cmd->add_flag("--force", flags->force,
                "keep --px-per-m, --drop-height or --time-scale even where the free fall and the "
                "ball's size both contradict it by more than 2x")
      ->group(group);
}

void SetScale(const ScaleFlags& flags, DetectStageConfig* config) {
  config->px_per_m = flags.px_per_m;
  config->drop_height_m = flags.drop_height_m;
  config->force = flags.force;
}

}  // namespace bouncefit::cli
