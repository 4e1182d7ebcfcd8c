#include "fit/fitted_ball_project.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "model/exported_sources.h"
#include "model/soft_ball_model.h"

namespace bouncefit {
namespace {

// The data's numbers are written "{:.17g}": they round-trip exactly (the data must be the
// fit's to the last bit).

void WriteText(const std::filesystem::path& path, std::string_view text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string Summary(const FitUpdate& u, const BallPreset& ball) {
  std::ostringstream s;
  return fmt::format("bouncefit fit of a {} ({:.4g} mm, {:.4g} g), model {}, method {}: RMS {:.4g} mm over {} "
                     "bounces from {:.4g} m",
                     ball.name, ball.diameter_m * 1000, ball.mass_kg * 1000, u.model, u.method, u.residual_m * 1000,
                     u.recorded_m.size(), u.drop_height_m);
}

// As a C++ string literal's contents.
std::string Escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') c = ' ';
    out += c;
  }
  return out;
}

// fitted_ball_data.cc: the fit as data.
std::string DataSource(const FitUpdate& u, const BallPreset& ball, const TetMesh& mesh) {
  std::ostringstream s;
  s << "// Written by bouncefit (fit --export): the fitted ball as data. Regenerate, do not edit.\n"
    << "#include \"fitted_ball.h\"\n\n#include <array>\n#include <vector>\n\n"
    << "namespace fitted_ball {\nnamespace {\n\n"
    << "// TetGen's mesh of the unit sphere the fit ran with (tetgen -pq"
    << mesh.params.radius_edge_ratio << "a" << mesh.params.max_volume
    << " on a geodesic sphere of frequency " << mesh.params.resolution << ").\n"
    << "const std::vector<std::array<double, 3>> kNodes = {\n";
  for (const auto& n : mesh.nodes)
    s << fmt::format("    {{{:.17g}, {:.17g}, {:.17g}}},\n", n[0], n[1], n[2]);
  s << "};\nconst std::vector<std::array<int, 4>> kTetras = {\n";
  for (const auto& t : mesh.tetras)
    s << "    {" << t[0] << ", " << t[1] << ", " << t[2] << ", " << t[3] << "},\n";
  s << "};\nconst std::vector<std::array<int, 3>> kFaces = {\n";
  for (const auto& f : mesh.faces) s << "    {" << f[0] << ", " << f[1] << ", " << f[2] << "},\n";
  s << "};\n\n}  // namespace\n\n"
    << "bouncefit::SoftBallWorldConfig Config() {\n"
    << "  bouncefit::SoftBallWorldConfig config;  // the model's fixed settings\n"
    << fmt::format("  config.time_step_s = {:.17g};  // s\n", u.time_step_s)
    << "  config.position_iterations = " << u.iterations << ";\n"
    << "  return config;\n}\n\n"
    << "bouncefit::SoftBallSpec Ball() {\n"
    << "  bouncefit::SoftBallSpec ball;\n"
    << fmt::format("  ball.radius_m = {:.17g};\n", ball.radius_m())
    << fmt::format("  ball.mass_kg = {:.17g};\n", ball.mass_kg)
    << "  ball.mesh = {&kNodes, &kTetras, &kFaces};\n"
    << "  ball.values = {\n";
  for (const auto& [name, v] : u.values) s << fmt::format("      {{\"{}\", {:.17g}}},\n", name, v);
  s << "  };\n  return ball;\n}\n\n"
    << "const char* Summary() { return \"" << Escaped(Summary(u, ball)) << "\"; }\n\n"
    << "}  // namespace fitted_ball\n";
  return s.str();
}

std::string Readme(const FitUpdate& u, const BallPreset& ball) {
  std::ostringstream s;
  s << "# fitted_ball\n\n" << Summary(u, ball) << ".\n\n"
    << "Needs only Bullet 3.24 (Debian: `apt-get install libbullet-dev cmake g++`):\n\n"
    << "    cmake -S . -B build && cmake --build build\n"
    << fmt::format("    build/fitted_ball {:.4g}   # bounce heights in metres, one per line\n\n", u.drop_height_m)
    << "`fitted_ball H` drops the ball from H m (its bottom above the floor, at rest) once, as\n"
    << "`bouncefit simulate` does: the same heights. In your own `btSoftRigidDynamicsWorld`,\n"
    << "`#include \"fitted_ball.h\"`, link `fitted_ball_lib` and call\n"
    << "`fitted_ball::AddFittedBall(world, centre)`; step with\n"
    << fmt::format("`world.stepSimulation(fitted_ball::kTimeStep, 0)` ({:.17g} s, the step the coefficients hold "
                   "for).\n\n",
                   u.time_step_s)
    << "`model/` is bouncefit's own simulation of the ball, unchanged; `fitted_ball_data.cc`\n"
    << "holds the mesh and every coefficient value of the fit.\n";
  return s.str();
}

}  // namespace

std::string FittedBallProjectUnavailable(const std::string& model) {
  if (model == "bullet-softbody") return {};
  if (model == "point-mass")
    return "the point-mass model is its formulas and coefficients.json: there is no Bullet body "
           "to build";
  return "the " + model + " model is not exported as a project (coefficients.json only)";
}

std::filesystem::path WriteFittedBallProject(const std::filesystem::path& dir, const FitUpdate& u,
                                             const BallPreset& ball) {
  if (const std::string why = FittedBallProjectUnavailable(u.model); !why.empty())
    throw std::runtime_error(why);
  const SoftBallModel model(ball);
  // Every value, defaults included: the shipped world reads each one by name.
  FitUpdate complete = u;
  std::string error;
  complete.values = model.Complete(u.values, &error);
  if (!error.empty()) throw std::runtime_error("cannot export the fitted ball: " + error);
  const auto mesh = model.Mesh(complete.values);
  const auto root = dir / "fitted_ball";
  // model/ is ours and globbed by the project: a file an older export shipped must not stay.
  std::error_code ignored;
  std::filesystem::remove_all(root / "model", ignored);
  for (const std::string& name : SoftBallWorldFileNames()) {
    const auto text = EmbeddedSoftBallWorldFile(name);
    if (!text) throw std::runtime_error("the soft ball's world file " + name + " is not built in");
    WriteText(root / "model" / name, *text);
  }
  for (const char* name : {"CMakeLists.txt", "fitted_ball.h", "fitted_ball.cc", "main.cc"}) {
    const auto text = EmbeddedFittedBallTemplate(name);
    if (!text) throw std::runtime_error(std::string("the fitted_ball file ") + name + " is not built in");
    WriteText(root / name, *text);
  }
  WriteText(root / "fitted_ball_data.cc", DataSource(complete, ball, *mesh));
  WriteText(root / "README.md", Readme(u, ball));
  return root;
}

}  // namespace bouncefit
