#include "cli/ball_flags.h"

#include "cli/number_checks.h"

namespace bouncefit::cli {

void AddBallFlags(CLI::App* cmd, BallFlags* flags) {
  const std::string group = "Ball";
  cmd->add_option("--ball", flags->name,
                  "ball preset: " + BallPresetNames() + " (default: the one the input names, else pingpong)")
      ->group(group);
  cmd->add_option("--diameter", flags->diameter_m, "ball diameter, m (overrides the preset's)")
      ->check(Positive())
      ->group(group);
  cmd->add_option("--mass", flags->mass_kg, "ball mass, kg (overrides the preset's)")
      ->check(Positive())
      ->group(group);
}

BallPreset ResolveBall(const BallFlags& flags, const BallFlags& named) {
  const std::string& name = !flags.name.empty() ? flags.name : !named.name.empty() ? named.name : "pingpong";
  return ResolveBallPreset(name, flags.diameter_m > 0 ? flags.diameter_m : named.diameter_m,
                           flags.mass_kg > 0 ? flags.mass_kg : named.mass_kg);
}

}  // namespace bouncefit::cli
