#include "cli/scale_flags.h"

#include "cli/number_checks.h"

namespace bouncefit::cli {

void AddScaleFlags(CLI::App* cmd, ScaleFlags* flags) {
  const std::string group = "Scale";
  cmd->add_option("--px-per-m", flags->px_per_m, "image scale, px/m (default: from the free fall)")
      ->check(Positive())
      ->group(group);
  // Given with --px-per-m, it is refused by CalibratorConfig::IsValid, where the rule lives.
  cmd->add_option("--drop-height", flags->drop_height_m, "release height of the ball bottom, m (sets the scale)")
      ->check(Positive())
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
