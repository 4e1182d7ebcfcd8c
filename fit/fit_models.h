#pragma once
// The models a fit can use, by name, for the CLI and the node.
#include <filesystem>
#include <memory>
#include <string>

#include "fit/ball_model.h"
#include "fit/ball_preset.h"
#include "fit/fit_session.h"

namespace bouncefit {

// "bullet-softbody" (alias "soft") or "point-mass"; throws std::invalid_argument otherwise.
std::unique_ptr<BallModel> MakeFitModel(const std::string& name, const BallPreset& ball);
std::string FitModelNames();  // "bullet-softbody, point-mass"

// Fills what a session needs to know about the model: the time step and iterations the
// coefficients hold for, and the warm start (the soft-body model's preset table for this
// ball, when it has one).
// fit/presets/soft_ball_<ball>.json (or $BOUNCEFIT_PRESETS_DIR/...); empty if none.
std::filesystem::path SoftBallPresetFile(const std::string& ball);
// A coefficient table: {"coefficients": {name: value | {"value": v}}} or {name: value}.
CoefficientValues LoadCoefficientTable(const std::filesystem::path& path);

void ConfigureSessionForModel(const BallModel& model, const BallPreset& ball,
                              FitSessionConfig* config);

}  // namespace bouncefit
