#pragma once
// `fit --export DIR` / `run --out DIR` for the classic soft ball: DIR/fitted_ball/, a small
// CMake project that needs only Bullet (libbullet-dev). It holds
//   model/*          the soft ball's world (model/soft_ball_world.h and what it includes),
//                    verbatim: the code the fit simulated with, so the export cannot drift;
//   fitted_ball_data.cc  the fit as data: the TetGen mesh it ran with (nodes, tetrahedra,
//                    faces), every coefficient value, the ball's size and mass, the step;
//   fitted_ball.h/.cc    AddFittedBall() for a user's btSoftRigidDynamicsWorld, the rebound
//                    boost as its pre-tick callback (fit/fitted_ball/);
//   main.cc          program fitted_ball: `fitted_ball H` prints the bounce heights of the
//                    ball dropped from H m, one run as `bouncefit simulate` does it;
//   CMakeLists.txt, README.md.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "fit/fit_session.h"
#include "model/ball_preset.h"

namespace bouncefit {

// Whether a fit of `model` is exported as a project; otherwise why not (one line).
std::string FittedBallProjectUnavailable(const std::string& model);

// Writes dir/fitted_ball/ for a "bullet-softbody" fit; returns that folder. Throws
// std::runtime_error (one line) when the model has no project or a file cannot be written.
std::filesystem::path WriteFittedBallProject(const std::filesystem::path& dir, const FitUpdate& update,
                                             const BallPreset& ball);

// The hand-written project files, by name (fit/fitted_ball/*), or nullopt.
std::optional<std::string_view> EmbeddedFittedBallTemplate(std::string_view file_name);

}  // namespace bouncefit
