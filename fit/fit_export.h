#pragma once
// Exports of a fit: the coefficients as JSON, and for the soft ball a CMake project that
// builds the fitted ball against Bullet (fit/fitted_ball_project.h).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "fit/fit_session.h"
#include "fit/fit_timeline.h"
#include "fit/fitted_ball_gltf.h"
#include "model/ball_preset.h"

namespace bouncefit {

// Every field of the update, coefficients as {"name": {"value", "sigma", "identifiable",
// "unit", "note"}}, plus the ball (name, mass, diameter) and every value the model ran with.
nlohmann::json FitUpdateToJson(const FitUpdate& update, const BallPreset& ball);

// Where a fit came from, for the animation's extras (every field optional).
struct FitExportContext {
  std::string clip;       // the clip (or peak file) the fit was made from
  std::string fitted_by;  // "run", "fit", ...
  const RecordedTrack* recorded = nullptr;  // the tracked ball, real seconds since the start apex
  // The fit's drops on the run's timeline (fit/fit_timeline.h): coefficients.json's "drops".
  const std::vector<FitDrop>* drops = nullptr;
  double run_s_per_real_s = 1;  // seconds of the run's clock per real second
};

// The fit as the animation's asset extras: the ball, the restitution law, drag, residual,
// the heights and where it was fitted.
nlohmann::json FitGltfExtras(const FitUpdate& update, const BallPreset& ball,
                             const FitExportContext& context = {});

// The fitted ball dropped from `drop_height_m` (m) as glTF at `path`
// (fit/fitted_ball_gltf.h), run with the step and iterations the fit holds for.
FittedBallGltf WriteFitGltf(const std::filesystem::path& path, const FitUpdate& update,
                            const BallPreset& ball, double drop_height_m,
                            const FitExportContext& context = {});

// Writes DIR/coefficients.json (with the context's drops and clock), DIR/fitted_ball.glb (the fitted ball dropped from the
// fit's own drop height; none when that is unknown) and the fitted_ball project (fit/fitted_ball_project.h; for a
// model without one, DIR/fitted_ball/README.md saying why); returns the paths written.
std::vector<std::filesystem::path> WriteFitExports(const std::filesystem::path& dir,
                                                   const FitUpdate& update,
                                                   const BallPreset& ball,
                                                   const FitExportContext& context = {});

}  // namespace bouncefit
