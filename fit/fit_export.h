#pragma once
// Exports of a fit: the coefficients as JSON, and as a C++ snippet that configures a
// btSoftBody the way the fitted model was run (Bullet field by field, with the time step
// and iteration count the coefficients hold for).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "fit/fit_session.h"
#include "model/ball_preset.h"

namespace bouncefit {

// Every field of the update, coefficients as {"name": {"value", "sigma", "identifiable",
// "unit", "note"}}, plus the ball (name, mass, diameter) and every value the model ran with.
nlohmann::json FitUpdateToJson(const FitUpdate& update, const BallPreset& ball);

// C++ (Bullet 3.24 classic btSoftBody) that applies the fitted values: material stiffness,
// m_cfg fields, unit conversions of pressure and volume conservation, piterations and the
// fixed time step; the artificial rebound boost as a documented per-step hook. Only for
// the "bullet-softbody" model; other models get a comment saying there is nothing to set.
std::string BtSoftBodySnippet(const FitUpdate& update, const BallPreset& ball);

// Writes DIR/coefficients.json, DIR/soft_body_config.cc and the fitted_ball project
// (fit/fitted_ball_project.h; for a model without one, DIR/fitted_ball/README.md saying
// why); returns the paths written.
std::vector<std::filesystem::path> WriteFitExports(const std::filesystem::path& dir,
                                                   const FitUpdate& update,
                                                   const BallPreset& ball);

}  // namespace bouncefit
