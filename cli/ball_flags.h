#pragma once
// The ball on every command that takes one: --ball, --diameter and --mass, one help text each.
#include <CLI/CLI.hpp>

#include <string>

#include "model/ball_preset.h"

namespace bouncefit::cli {

// A ball as named on the command line or by an input (a sample clip, a coefficients file):
// an empty name or a 0 size or mass is one not given.
struct BallFlags {
  std::string name;
  double diameter_m = 0;
  double mass_kg = 0;
};

void AddBallFlags(CLI::App* cmd, BallFlags* flags);

// The preset the flags name, else the one `named` names, else pingpong; its diameter and mass
// from the flags, else from `named`, else the preset's. Throws std::invalid_argument for an
// unknown name.
BallPreset ResolveBall(const BallFlags& flags, const BallFlags& named = {});

}  // namespace bouncefit::cli
