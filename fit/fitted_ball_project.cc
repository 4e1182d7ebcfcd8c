#include "fit/fitted_ball_project.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "model/exported_sources.h"
#include "model/soft_ball_model.h"

namespace bouncefit {
namespace {

// Round-trips a double exactly (the data must be the fit's to the last bit).
std::string Exact(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string G(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

void WriteText(const std::filesystem::path& path, std::string_view text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string Summary(const FitUpdate& u, const BallPreset& ball) {
  std::ostringstream s;
  s << "bouncefit fit of a " << ball.name << " (" << G(ball.diameter_m * 1000) << " mm, "
    << G(ball.mass_kg * 1000) << " g), model " << u.model << ", method " << u.method << ": RMS "
    << G(u.residual_m * 1000) << " mm over " << u.recorded_m.size() << " bounces from "
    << G(u.drop_height_m) << " m";
  return s.str();
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
    s << "    {" << Exact(n[0]) << ", " << Exact(n[1]) << ", " << Exact(n[2]) << "},\n";
  s << "};\nconst std::vector<std::array<int, 4>> kTetras = {\n";
  for (const auto& t : mesh.tetras)
    s << "    {" << t[0] << ", " << t[1] << ", " << t[2] << ", " << t[3] << "},\n";
  s << "};\nconst std::vector<std::array<int, 3>> kFaces = {\n";
  for (const auto& f : mesh.faces) s << "    {" << f[0] << ", " << f[1] << ", " << f[2] << "},\n";
  s << "};\n\n}  // namespace\n\n"
    << "bouncefit::SoftBallWorldConfig Config() {\n"
    << "  bouncefit::SoftBallWorldConfig config;  // the model's fixed settings\n"
    << "  config.time_step_s = " << Exact(u.time_step_s) << ";  // s\n"
    << "  config.position_iterations = " << u.iterations << ";\n"
    << "  return config;\n}\n\n"
    << "bouncefit::SoftBallSpec Ball() {\n"
    << "  bouncefit::SoftBallSpec ball;\n"
    << "  ball.radius_m = " << Exact(ball.radius_m()) << ";\n"
    << "  ball.mass_kg = " << Exact(ball.mass_kg) << ";\n"
    << "  ball.mesh = {&kNodes, &kTetras, &kFaces};\n"
    << "  ball.values = {\n";
  for (const auto& [name, v] : u.values) s << "      {\"" << name << "\", " << Exact(v) << "},\n";
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
    << "    build/fitted_ball " << G(u.drop_height_m) << "   # bounce heights in metres, one per line\n\n"
    << "`fitted_ball H` drops the ball from H m (its bottom above the floor, at rest) once, as\n"
    << "`bouncefit simulate` does: the same heights. In your own `btSoftRigidDynamicsWorld`,\n"
    << "`#include \"fitted_ball.h\"`, link `fitted_ball_lib` and call\n"
    << "`fitted_ball::AddFittedBall(world, centre)`; step with\n"
    << "`world.stepSimulation(fitted_ball::kTimeStep, 0)` (" << Exact(u.time_step_s)
    << " s, the step the coefficients hold for).\n\n"
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
