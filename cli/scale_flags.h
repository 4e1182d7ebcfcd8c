#pragma once
// The scale a measurement is read in metres with, as given on `run` and `detect`: --px-per-m
// or --drop-height (the calibrator's config says which may go together), and --force.
#include <CLI/CLI.hpp>

#include "pipeline/detect_stage.h"

namespace bouncefit::cli {

struct ScaleFlags {
  double px_per_m = 0;       // 0: from the free fall
  double drop_height_m = 0;  // > 0: the scale from the ball's release height
  bool force = false;        // keep a scale or clock flag the measurement contradicts
};

void AddScaleFlags(CLI::App* cmd, ScaleFlags* flags);

// The detect stage reads the scale given.
void SetScale(const ScaleFlags& flags, DetectStageConfig* config);

}  // namespace bouncefit::cli
