#include "fit/fit_export.h"

#include "fit/fitted_ball_project.h"
#include "model/soft_ball_model.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bouncefit {

namespace {

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

double Value(const FitUpdate& u, const std::string& name, double fallback) {
  auto it = u.values.find(name);
  return it != u.values.end() ? it->second : fallback;
}

std::string G(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

nlohmann::json FitUpdateToJson(const FitUpdate& u, const BallPreset& ball) {
  nlohmann::json coeffs = nlohmann::json::object();
  for (const auto& c : u.coefficients)
    coeffs[c.name] = {{"value", Num(c.value)},   {"sigma", Num(c.sigma)},
                      {"identifiable", c.identifiable}, {"unit", c.unit},
                      {"note", c.note}};
  nlohmann::json values = nlohmann::json::object();
  for (const auto& [name, v] : u.values) values[name] = Num(v);
  return {{"model", u.model},
          {"method", u.method},
          {"final", u.final},
          {"sequence", u.sequence},
          {"after_bounce", u.after_bounce},
          {"ball", {{"name", ball.name}, {"mass_kg", ball.mass_kg}, {"diameter_m", ball.diameter_m}}},
          {"time_step_s", u.time_step_s},
          {"iterations", u.iterations},
          {"drop_height_m", u.drop_height_m},
          {"coefficients", coeffs},
          {"values", values},
          {"no_effect", u.no_effect},
          {"unidentified", u.unidentified},
          {"recorded_m", u.recorded_m},
          {"simulated_m", u.simulated_m},
          {"residual_m", Num(u.residual_m)},
          {"segment_simulated_m", u.segment_simulated_m},
          {"segment_residual_m", Num(u.segment_residual_m)},
          {"free_run_mean_m", u.free_run_mean_m},
          {"free_run_sd_m", u.free_run_sd_m},
          {"free_run_residual_m", Num(u.free_run_residual_m)},
          {"warning", u.warning},
          {"evaluations", u.evaluations},
          {"wall_time_s", u.wall_time_s}};
}

std::string BtSoftBodySnippet(const FitUpdate& u, const BallPreset& ball) {
  std::ostringstream s;
  s << "// bouncefit fit: " << ball.name << " (" << G(ball.diameter_m * 1000) << " mm, "
    << G(ball.mass_kg * 1000) << " g), model " << u.model << ", method " << u.method
    << ", RMS height residual " << G(u.residual_m * 1000) << " mm over " << u.recorded_m.size()
    << " bounces from " << G(u.drop_height_m) << " m.\n";
  if (u.model != "bullet-softbody") {
    s << "// This fit is of the point-mass model: there is no btSoftBody to configure.\n";
    for (const auto& [name, v] : u.values) s << "// " << name << " = " << G(v) << "\n";
    return s.str();
  }
  // The fixed settings of the model the coefficients were fitted with.
  const SoftBallModelConfig model;
  const double r = ball.radius_m(), m = ball.mass_kg, g = model.gravity_mps2;
  const double pi = 3.14159265358979323846;
  const double volume0 = 4.0 / 3.0 * pi * r * r * r;
  const double pressure = Value(u, "pressure", 0);
  const double vc = Value(u, "volume_conservation", 0);
  s << "// The coefficients hold for this time step and iteration count only (Bullet's\n"
       "// damping and stiffness act per step and per position iteration).\n"
    << "constexpr btScalar kFixedTimeStep = btScalar(" << G(u.time_step_s) << ");  // s\n"
    << "constexpr int kPositionIterations = " << u.iterations << ";\n"
    << "// Mesh: tetgen -pq" << G(Value(u, "radius_edge_ratio", 2)) << "a"
    << G(Value(u, "max_volume", 0.1)) << " on a unit geodesic sphere of frequency "
    << G(Value(u, "mesh_resolution", 3)) << ", scaled to r = " << G(r) << " m.\n"
    << "// Step with: world->stepSimulation(kFixedTimeStep, 0);\n"
    << "inline void ConfigureFittedBall(btSoftBody* sb, btSoftBodyWorldInfo* info) {\n"
    << "  info->m_gravity = btVector3(0, btScalar(-" << G(g) << "), 0);  // soft bodies use this\n"
    << "  info->air_density = btScalar(" << G(model.air_density_kgpm3) << ");\n"
    << "  btSoftBody::Material* mat = sb->m_materials[0];\n"
    << "  mat->m_kLST = btScalar(" << G(Value(u, "linear_stiffness", 1)) << ");\n"
    << "  mat->m_kAST = btScalar(" << G(Value(u, "angular_stiffness", 1))
    << ");  // unused by Bullet 3.24's solver\n"
    << "  mat->m_kVST = btScalar(" << G(Value(u, "volume_stiffness", 1))
    << ");  // unused by Bullet 3.24's solver\n"
    << "  sb->setTotalMass(btScalar(" << G(m) << "), false);\n"
    << "  btSoftBody::Config& k = sb->m_cfg;\n"
    << "  // pressure " << G(pressure) << " x m*g/(pi r^2), times the rest volume\n"
    << "  k.kPR = btScalar(" << G(pressure * m * g * volume0 / (pi * r * r)) << ");\n"
    << "  // volume conservation " << G(vc) << " x m*g/(pi r^2), per rest volume\n"
    << "  k.kVC = btScalar(" << G(vc * m * g / (pi * r * r * volume0)) << ");\n"
    << "  k.kDP = btScalar(" << G(Value(u, "damping", 0)) << ");\n"
    << "  k.kDG = btScalar(" << G(Value(u, "drag", 0)) << ");\n"
    << "  k.kLF = btScalar(" << G(Value(u, "lift", 0)) << ");\n"
    << "  k.kSR_SPLT_CL = btScalar(" << G(Value(u, "soft_rigid_impulse_split", 0.5)) << ");\n"
    << "  k.kSK_SPLT_CL = btScalar(" << G(Value(u, "soft_kinetic_impulse_split", 0.5)) << ");\n"
    << "  k.kSS_SPLT_CL = btScalar(" << G(Value(u, "soft_soft_impulse_split", 0.5)) << ");\n"
    << "  k.kKHR = btScalar(" << G(Value(u, "contact_hardness", 0.1))
    << ");  // static floor contact\n"
    << "  k.kDF = 1;  // floor friction " << G(Value(u, "floor_friction", 0.5))
    << " goes on the floor body\n"
    << "  k.aeromodel = btSoftBody::eAeroModel::V_TwoSidedLiftDrag;\n"
    << "  k.piterations = kPositionIterations;\n"
    << "  k.viterations = 0;\n"
    << "  k.diterations = 0;\n"
    << "  k.collisions = btSoftBody::fCollision::SDF_RS;\n"
    << "  sb->getCollisionShape()->setMargin(btScalar(" << G(model.margin_per_radius * r)
    << "));  // put the floor's top face this much below y = 0\n"
    << "  info->m_sparsesdf.setDefaultVoxelsz(btScalar(" << G(model.sdf_voxel_per_radius * r)
    << "));\n"
    << "  info->m_sparsesdf.Reset();\n"
    << "  sb->setPose(true, false);  // rest volume for kVC\n"
    << "}\n"
    << "// Before release the fit let the ball float weightless for " << G(model.settle_time_s)
    << " s with kDP = " << G(model.settle_damping) << ",\n"
    << "// so pressure and links start in equilibrium; do the same.\n";
  const double boost = Value(u, "rebound_boost", 0);
  s << "// Artificial rebound boost (not Bullet; the paper's extra force): "
    << (boost > 0 ? "" : "0, nothing to do.") << "\n";
  if (boost > 0)
    s << "// once per contact, when the ball leaves the floor, add to every node\n"
      << "//   sb->addVelocity(btVector3(0, btScalar(" << G(boost)
      << ") * impact_speed, 0));\n"
      << "// impact_speed = downward speed of the centre of mass just before contact.\n";
  const double slope = Value(u, "rebound_boost_per_mps", 0);
  if (boost > 0 && slope != 0)
    s << "// with the boost falling with impact speed: replace " << G(boost) << " by\n"
      << "//   max(0, " << G(boost) << " - " << G(slope) << " * (impact_speed - 4.43))\n";
  return s.str();
}

std::vector<std::filesystem::path> WriteFitExports(const std::filesystem::path& dir,
                                                   const FitUpdate& u, const BallPreset& ball) {
  std::filesystem::create_directories(dir);
  const auto json_path = dir / "coefficients.json";
  const auto cc_path = dir / "soft_body_config.cc";
  {
    std::ofstream out(json_path);
    out << FitUpdateToJson(u, ball).dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + json_path.string());
  }
  {
    std::ofstream out(cc_path);
    out << BtSoftBodySnippet(u, ball);
    if (!out) throw std::runtime_error("cannot write " + cc_path.string());
  }
  std::vector<std::filesystem::path> written{json_path, cc_path};
  if (FittedBallProjectUnavailable(u.model).empty()) {
    written.push_back(WriteFittedBallProject(dir, u, ball));
  } else {  // said where a user looks for it
    const auto note = dir / "fitted_ball" / "README.md";
    std::filesystem::create_directories(note.parent_path());
    std::ofstream out(note);
    out << "# fitted_ball: nothing to build\n\n" << FittedBallProjectUnavailable(u.model) << ".\n";
    if (!out) throw std::runtime_error("cannot write " + note.string());
    written.push_back(note);
  }
  return written;
}

}  // namespace bouncefit
