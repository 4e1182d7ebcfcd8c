#include "model/soft_ball_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace bouncefit {
namespace {

// Every coefficient, in the paper's priority order, then the ones the paper does not list.
// The Bullet field each one sets is in docs/MODEL.md.
std::vector<CoefficientSpec> MakeSpecs() {
  return {
      {"linear_stiffness", "", 0.5, 0.0, 1.0, false,
       "Material::m_kLST, stiffness of the tetrahedron edges (links), per position iteration"},
      {"angular_stiffness", "", 1.0, 0.0, 1.0, false,
       "Material::m_kAST; stored but not used by Bullet 3.24's solver (no effect)"},
      {"volume_stiffness", "", 1.0, 0.0, 1.0, false,
       "Material::m_kVST; stored but not used by Bullet 3.24's solver (no effect)"},
      {"pressure", "m*g/(pi*r^2)", 0.5, -10.0, 100.0, false,
       "Config::kPR, internal gas pressure (p = kPR/volume) in units of the ball's weight over "
       "its cross-section"},
      {"damping", "", 0.0, 0.0, 1.0, false,
       "Config::kDP, fraction of node velocity removed every step"},
      {"drag", "", 0.47, 0.0, 10.0, false,
       "Config::kDG, air drag coefficient Cd (two-sided vertex aero model: F = Cd*rho*v^2*A/2)"},
      {"lift", "", 0.0, 0.0, 10.0, false,
       "Config::kLF, aerodynamic lift coefficient (acts across the flow)"},
      {"soft_rigid_impulse_split", "", 0.5, 0.0, 1.0, false,
       "Config::kSR_SPLT_CL, soft/rigid impulse split; cluster collisions only (no effect here)"},
      {"soft_kinetic_impulse_split", "", 0.5, 0.0, 1.0, false,
       "Config::kSK_SPLT_CL, soft/kinetic impulse split; cluster collisions only (no effect here)"},
      {"soft_soft_impulse_split", "", 0.5, 0.0, 1.0, false,
       "Config::kSS_SPLT_CL, soft/soft impulse split; cluster collisions only (no effect here)"},
      {"mesh_resolution", "", 3, 2, 6, true,
       "geodesic frequency of the sphere surface handed to tetgen (10*f^2+2 surface vertices)"},
      {"radius_edge_ratio", "", 2.0, 1.2, 3.0, false,
       "tetgen -q, max radius/edge ratio of a tetrahedron (rounded to 0.01)"},
      {"max_volume", "unit sphere", 0.1, 0.01, 0.1, false,
       "tetgen -a, max tetrahedron volume on the unit sphere (volume 4.19; rounded to 1e-4)"},
      {"volume_conservation", "m*g/(pi*r^2)", 70.0, 0.0, 1000.0, false,
       "Config::kVC, restoring pressure per relative volume loss, in the ball's weight over its "
       "cross-section"},
      {"contact_hardness", "", 0.3, 0.0, 1.0, false,
       "Config::kKHR, fraction of the floor penetration removed per iteration (static contact)"},
      {"floor_friction", "", 0.5, 0.0, 1.0, false,
       "friction of the floor (Config::kDF = 1, so this is the contact friction)"},
      {"floor_restitution", "", 0.0, 0.0, 1.0, false,
       "btCollisionObject restitution of the floor; soft-rigid contacts ignore it (no effect)"},
      {"rebound_boost", "", 0.0, 0.0, 1.0, false,
       "artificial, not Bullet: upward velocity given to every node when the ball leaves the "
       "floor, as a fraction of the impact speed (the paper's 'artificial extra force')"},
      {"rebound_boost_per_mps", "1/(m/s)", 0.0, -0.1, 0.2, false,
       "artificial: the rebound boost's loss per m/s of impact speed above 4.43 m/s (a 1 m "
       "drop), so restitution can fall with speed as a real ball's does"},
      {"rebound_restitution", "", 0.0, 0.0, 1.0, false,
       "artificial, replaces the boost when > 0: the ball leaves every impact at this "
       "restitution (minus the slope below) times the impact speed (0: Bullet's rebound + boost)"},
      {"rebound_restitution_per_mps", "1/(m/s)", 0.0, 0.0, 0.2, false,
       "artificial: loss of rebound_restitution per m/s of impact speed, e(v) = e0 - k v"},
  };
}

const std::vector<CoefficientSpec>& Specs() {
  static const std::vector<CoefficientSpec> specs = MakeSpecs();
  return specs;
}
// The mesh parameters among the coefficients (the rest are Bullet's: model/soft_ball_world.cc).
TetMeshParams MeshParams(const CoefficientValues& v) {
  TetMeshParams p;
  p.resolution = static_cast<int>(std::lround(v.at("mesh_resolution")));
  p.radius_edge_ratio = v.at("radius_edge_ratio");
  p.max_volume = v.at("max_volume");
  return p;
}

}  // namespace

SoftBallModel::SoftBallModel(BallPreset ball, SoftBallModelConfig config)
    : ball_(std::move(ball)), config_(std::move(config)) {
  if (const std::string err = config_.Validate(); !err.empty()) throw std::invalid_argument(err);
  if (!(ball_.diameter_m > 0) || !(ball_.mass_kg > 0))
    throw std::invalid_argument("ball '" + ball_.name + "' needs a diameter and a mass > 0");
}

std::vector<CoefficientSpec> SoftBallModel::Coefficients() const { return Specs(); }

CoefficientValues SoftBallModel::Complete(const CoefficientValues& values, std::string* error) const {
  error->clear();
  CoefficientValues out;
  for (const auto& s : Specs()) out[s.name] = s.default_value;
  for (const auto& [name, value] : values) {
    const auto it = std::find_if(Specs().begin(), Specs().end(),
                                 [&](const CoefficientSpec& s) { return s.name == name; });
    if (it == Specs().end()) {
      *error = "unknown coefficient '" + name + "' (see simulate --list-coeffs)";
      return {};
    }
    double v = value;
    if (it->discrete) v = std::round(v);
    if (!std::isfinite(v) || v < it->lower || v > it->upper) {
      *error = fmt::format("coefficient {} = {:.6g} is outside [{:.4g}, {:.4g}]", name, value, it->lower, it->upper);
      return {};
    }
    out[name] = v;
  }
  return out;
}

std::shared_ptr<const TetMesh> SoftBallModel::Mesh(const CoefficientValues& values) const {
  std::string error;
  const CoefficientValues all = Complete(values, &error);
  if (!error.empty()) throw std::invalid_argument(error);
  return GetTetMesh(MeshParams(all), config_.tetgen);
}

SimulationResult SoftBallModel::Simulate(const CoefficientValues& values,
                                         const SimulationOptions& options) const {
  SimulationResult failed;
  std::string error = SimulationOptionsError(options);
  SoftBallSpec spec;
  if (error.empty()) spec.values = Complete(values, &error);
  std::shared_ptr<const TetMesh> mesh;
  if (error.empty()) {
    try {
      mesh = GetTetMesh(MeshParams(spec.values), config_.tetgen);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (!error.empty()) {
    failed.failure = error;
    return failed;
  }
  spec.radius_m = ball_.radius_m();
  spec.mass_kg = ball_.mass_kg;
  spec.mesh = {&mesh->nodes, &mesh->tetras, &mesh->faces};
  return SimulateSoftBallDrop(config_, spec, options);
}

CoefficientValues ParseCoefficientList(const std::string& text) {
  CoefficientValues out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto trim = [](std::string s) {
      const auto b = s.find_first_not_of(" \t");
      const auto e = s.find_last_not_of(" \t");
      return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
    };
    item = trim(item);
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("expected name=value, got '" + item + "'");
    const std::string name = trim(item.substr(0, eq));
    const std::string value = trim(item.substr(eq + 1));
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (name.empty() || value.empty() || *end || !std::isfinite(v))
      throw std::invalid_argument("bad coefficient '" + item + "'");
    out[name] = v;
  }
  return out;
}

}  // namespace bouncefit
