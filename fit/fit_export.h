#pragma once
// Exports of a fit: the coefficients as JSON, and for the soft ball a CMake project that
// builds the fitted ball against Bullet (fit/fitted_ball_project.h).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "fit/fit_session.h"
#include "model/ball_preset.h"

namespace bouncefit {

// Every field of the update, coefficients as {"name": {"value", "sigma", "identifiable",
// "unit", "note"}}, plus the ball (name, mass, diameter) and every value the model ran with.
nlohmann::json FitUpdateToJson(const FitUpdate& update, const BallPreset& ball);

// Writes DIR/coefficients.json and the fitted_ball project
// (fit/fitted_ball_project.h; for a model without one, DIR/fitted_ball/README.md saying
// why); returns the paths written.
std::vector<std::filesystem::path> WriteFitExports(const std::filesystem::path& dir,
                                                   const FitUpdate& update,
                                                   const BallPreset& ball);

}  // namespace bouncefit
