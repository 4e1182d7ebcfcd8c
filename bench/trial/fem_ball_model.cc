#include "bench/trial/fem_ball_model.h"

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletSoftBody/btDeformableBodySolver.h>
#include <BulletSoftBody/btDeformableGravityForce.h>
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btDeformableNeoHookeanForce.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

#include "model/soft_ball_model.h"  // MeasureBounces: the same measurement as the classic ball

namespace bouncefit {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<CoefficientSpec> Specs(const BallPreset& ball) {
  return {
      {"youngs_modulus", "Pa", 1e5, 1e3, 1e9, false,
       "Young's modulus E of the ball's material (Neo-Hookean, with poisson_ratio)"},
      {"poisson_ratio", "", 0.3, 0.0, 0.49, false,
       "Poisson's ratio nu (0.5 would be incompressible)"},
      {"damping", "s", 1e-4, 0.0, 0.05, false,
       "strain-rate damping of the Neo-Hookean force: damping stress = damping * (mu, lambda) "
       "times the strain rate (Bullet's default 0.05 s)"},
      {"drag", "", ball.drag_coefficient, 0.0, 10.0, false,
       "air drag coefficient Cd on the ball's centre: F = Cd*rho*v^2*pi*r^2/2"},
      {"floor_friction", "", 0.5, 0.0, 1.0, false, "Coulomb friction of the node-floor contact"},
      {"mesh_resolution", "", 3, 2, 6, true,
       "geodesic frequency of the sphere surface handed to tetgen (10*f^2+2 surface vertices)"},
      {"radius_edge_ratio", "", 2.0, 1.2, 3.0, false,
       "tetgen -q, max radius/edge ratio of a tetrahedron (rounded to 0.01)"},
      {"max_volume", "unit sphere", 0.1, 0.01, 0.1, false,
       "tetgen -a, max tetrahedron volume on the unit sphere (volume 4.19; rounded to 1e-4)"},
  };
}

struct Coeffs {
  double E, nu, damping, drag, friction;
  TetMeshParams mesh;
  static Coeffs From(const CoefficientValues& v) {
    Coeffs c;
    c.E = v.at("youngs_modulus");
    c.nu = v.at("poisson_ratio");
    c.damping = v.at("damping");
    c.drag = v.at("drag");
    c.friction = v.at("floor_friction");
    c.mesh.resolution = static_cast<int>(std::lround(v.at("mesh_resolution")));
    c.mesh.radius_edge_ratio = v.at("radius_edge_ratio");
    c.mesh.max_volume = v.at("max_volume");
    return c;
  }
  double Mu() const { return E / (2 * (1 + nu)); }
  double Lambda() const { return E * nu / ((1 + nu) * (1 - 2 * nu)); }
};

using Vec3 = std::array<double, 3>;
Vec3 Sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double Norm(const Vec3& a) { return std::sqrt(Dot(a, a)); }

// Signed volume of a tetrahedron (positive when (b-a, c-a, d-a) is right-handed).
double TetVolume(const TetMesh& m, const std::array<int, 4>& t) {
  const auto& n = m.nodes;
  return Dot(Sub(n[t[1]], n[t[0]]), Cross(Sub(n[t[2]], n[t[0]]), Sub(n[t[3]], n[t[0]]))) / 6;
}

// Shortest altitude (vertex to opposite face) over all tetrahedra of the unit mesh.
double MinAltitude(const TetMesh& m) {
  double best = 1e300;
  for (const auto& t : m.tetras) {
    const double v = std::abs(TetVolume(m, t));
    for (int skip = 0; skip < 4; ++skip) {
      Vec3 p[3];
      for (int k = 0, j = 0; k < 4; ++k)
        if (k != skip) p[j++] = m.nodes[static_cast<size_t>(t[static_cast<size_t>(k)])];
      const double area = Norm(Cross(Sub(p[1], p[0]), Sub(p[2], p[0]))) / 2;
      if (area > 0) best = std::min(best, 3 * v / area);
    }
  }
  return best;
}

double MeshVolume(const TetMesh& m) {
  double v = 0;
  for (const auto& t : m.tetras) v += std::abs(TetVolume(m, t));
  return v;
}

// One deformable world with its floor and ball; Bullet's world owns none of these.
struct World {
  std::unique_ptr<btSoftBodyRigidBodyCollisionConfiguration> collision_config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btDeformableBodySolver> body_solver;
  std::unique_ptr<btDeformableMultiBodyConstraintSolver> solver;
  std::unique_ptr<btDeformableMultiBodyDynamicsWorld> world;
  std::unique_ptr<btBoxShape> floor_shape;
  std::unique_ptr<btRigidBody> floor;
  std::unique_ptr<btSoftBody> ball;
  std::unique_ptr<btDeformableGravityForce> gravity;
  std::unique_ptr<btDeformableNeoHookeanForce> elasticity;

  ~World() {
    if (world && ball) world->removeSoftBody(ball.get());
    if (world && floor) world->removeRigidBody(floor.get());
    ball.reset();
    floor.reset();
    if (world) world->getWorldInfo().m_sparsesdf.Reset();
    world.reset();
  }
};

// Builds the world of one run; returns the undeformed mesh's x extent / y extent.
double BuildWorld(const BallPreset& ball, const FemBallModelConfig& cfg, const Coeffs& c,
                  const TetMesh& mesh, double drop_height_m, World* w) {
  const double r = ball.radius_m();
  const double margin = cfg.margin_per_radius * r;
  const btVector3 g(0, -btScalar(cfg.gravity_mps2), 0);

  w->collision_config = std::make_unique<btSoftBodyRigidBodyCollisionConfiguration>();
  w->dispatcher = std::make_unique<btCollisionDispatcher>(w->collision_config.get());
  w->broadphase = std::make_unique<btDbvtBroadphase>();
  w->body_solver = std::make_unique<btDeformableBodySolver>();
  w->solver = std::make_unique<btDeformableMultiBodyConstraintSolver>();
  w->solver->setDeformableSolver(w->body_solver.get());
  w->world = std::make_unique<btDeformableMultiBodyDynamicsWorld>(
      w->dispatcher.get(), w->broadphase.get(), w->solver.get(), w->collision_config.get(),
      w->body_solver.get());
  w->world->setGravity(g);
  btSoftBodyWorldInfo& info = w->world->getWorldInfo();
  info.m_gravity = g;
  info.air_density = btScalar(cfg.air_density_kgpm3);
  info.m_sparsesdf.setDefaultVoxelsz(btScalar(cfg.sdf_voxel_per_radius * r));
  info.m_sparsesdf.Reset();
  w->world->setImplicit(cfg.implicit);
  w->world->setLineSearch(false);
  w->world->setUseProjection(cfg.use_projection);
  w->world->getSolverInfo().m_deformable_erp = btScalar(cfg.contact_erp);

  // Floor: a box (SDF contact needs a convex shape), top face one margin below y = 0.
  const btScalar half_size = btScalar(std::max(2.0, 20 * r));
  const btScalar half_thickness = btScalar(std::max(0.5, 5 * r));
  w->floor_shape = std::make_unique<btBoxShape>(btVector3(half_size, half_thickness, half_size));
  btRigidBody::btRigidBodyConstructionInfo floor_ci(0, nullptr, w->floor_shape.get());
  floor_ci.m_startWorldTransform.setIdentity();
  floor_ci.m_startWorldTransform.setOrigin(btVector3(0, -half_thickness - btScalar(margin), 0));
  floor_ci.m_friction = btScalar(c.friction);
  w->floor = std::make_unique<btRigidBody>(floor_ci);
  w->world->addRigidBody(w->floor.get());

  // Ball: the unit mesh with its lowest node straight down (as the classic model turns its
  // mesh, a vertex first), built at the origin so that Bullet's rest-shape matrices are
  // computed in small coordinates, then moved up to the drop height.
  const double t = (1 + std::sqrt(5.0)) / 2, n0 = std::sqrt(1 + t * t);
  const Vec3 a{-1 / n0, t / n0, 0}, b{0, -1, 0};
  const Vec3 v = Cross(a, b);
  const double cth = Dot(a, b), k = 1 / (1 + cth);
  auto rotate = [&](const Vec3& p) {  // Rodrigues: a onto b
    const Vec3 vxp = Cross(v, p);
    const Vec3 vxvxp = Cross(v, vxp);
    return Vec3{p[0] + vxp[0] + k * vxvxp[0], p[1] + vxp[1] + k * vxvxp[1],
                p[2] + vxp[2] + k * vxvxp[2]};
  };
  std::vector<btVector3> x(mesh.nodes.size());
  double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
  for (size_t i = 0; i < x.size(); ++i) {
    const Vec3 p = rotate(mesh.nodes[i]);
    xmin = std::min(xmin, p[0]);
    xmax = std::max(xmax, p[0]);
    ymin = std::min(ymin, p[1]);
    ymax = std::max(ymax, p[1]);
    x[i] = btVector3(btScalar(p[0] * r), btScalar(p[1] * r), btScalar(p[2] * r));
  }
  w->ball = std::make_unique<btSoftBody>(&info, static_cast<int>(x.size()), x.data(), nullptr);
  btSoftBody* sb = w->ball.get();
  // Lumped masses: a quarter of each tetrahedron's mass to each of its nodes. Tetrahedra
  // are appended positively oriented (an inverted one makes the Neo-Hookean force blow up).
  const double density = ball.mass_kg / (MeshVolume(mesh) * r * r * r);
  std::vector<double> node_mass(x.size(), 0);
  for (const auto& tet : mesh.tetras) {
    std::array<int, 4> o = tet;
    const double vol = TetVolume(mesh, tet);
    if (vol < 0) std::swap(o[2], o[3]);
    sb->appendTetra(o[0], o[1], o[2], o[3]);
    for (int n : o) node_mass[static_cast<size_t>(n)] += density * std::abs(vol) * r * r * r / 4;
  }
  // Links carry no force in the deformable solver, but Bullet builds its node tree from
  // their adjacency (without them rebuildNodeTree never finishes).
  std::set<std::pair<int, int>> edges;
  for (const auto& tet : mesh.tetras)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const int p = tet[static_cast<size_t>(i)], q = tet[static_cast<size_t>(j)];
        if (edges.insert({std::min(p, q), std::max(p, q)}).second) sb->appendLink(p, q, nullptr, false);
      }
  for (const auto& f : mesh.faces) sb->appendFace(f[0], f[1], f[2]);
  for (size_t i = 0; i < x.size(); ++i)
    sb->m_nodes[static_cast<int>(i)].m_im = node_mass[i] > 0 ? btScalar(1 / node_mass[i]) : 0;
  sb->m_bUpdateRtCst = true;
  sb->initializeDmInverse();
  // Bullet's TetraScratch has no constructor: GCC warns inside Bullet's header here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  sb->m_tetraScratches.resize(sb->m_tetras.size());
  sb->m_tetraScratchesTn.resize(sb->m_tetras.size());
#pragma GCC diagnostic pop
  sb->translate(btVector3(0, btScalar(drop_height_m + r), 0));

  sb->getCollisionShape()->setMargin(btScalar(margin));
  sb->m_cfg.kKHR = 1;
  sb->m_cfg.kCHR = 1;
  sb->m_cfg.kDF = btScalar(c.friction);
  sb->m_cfg.collisions = btSoftBody::fCollision::SDF_RD | btSoftBody::fCollision::SDF_RDN;
  sb->m_sleepingThreshold = 0;
  sb->setActivationState(DISABLE_DEACTIVATION);
  w->world->addSoftBody(sb);

  w->gravity = std::make_unique<btDeformableGravityForce>(g);
  w->world->addForce(sb, w->gravity.get());
  w->elasticity = std::make_unique<btDeformableNeoHookeanForce>(
      btScalar(c.Mu()), btScalar(c.Lambda()), btScalar(c.damping));
  w->world->addForce(sb, w->elasticity.get());
  return (xmax - xmin) / (ymax - ymin);
}

struct State {
  bool finite = true;
  double com_y = 0, com_vx = 0, com_vy = 0, com_vz = 0, min_y = 0, max_y = 0, min_x = 0, max_x = 0;
  double max_dist = 0, max_speed = 0;
};

State Measure(const btSoftBody& sb) {
  State s;
  double m = 0, cx = 0, cy = 0, cz = 0, vx = 0, vy = 0, vz = 0, speed2 = 0;
  s.min_y = s.min_x = 1e300;
  s.max_y = s.max_x = -1e300;
  for (int i = 0; i < sb.m_nodes.size(); ++i) {
    const btSoftBody::Node& n = sb.m_nodes[i];
    const double mi = n.m_im > 0 ? 1 / double(n.m_im) : 0;
    m += mi;
    cx += mi * n.m_x.x();
    cy += mi * n.m_x.y();
    cz += mi * n.m_x.z();
    vx += mi * n.m_v.x();
    vy += mi * n.m_v.y();
    vz += mi * n.m_v.z();
    speed2 = std::max(speed2, double(n.m_v.length2()));
    s.min_y = std::min(s.min_y, double(n.m_x.y()));
    s.max_y = std::max(s.max_y, double(n.m_x.y()));
    s.min_x = std::min(s.min_x, double(n.m_x.x()));
    s.max_x = std::max(s.max_x, double(n.m_x.x()));
  }
  if (!std::isfinite(cx + cy + cz + vx + vy + vz + speed2) || !(m > 0)) {
    s.finite = false;
    return s;
  }
  s.com_y = cy / m;
  s.com_vx = vx / m;
  s.com_vy = vy / m;
  s.com_vz = vz / m;
  s.max_speed = std::sqrt(speed2);
  const btVector3 com(btScalar(cx / m), btScalar(cy / m), btScalar(cz / m));
  for (int i = 0; i < sb.m_nodes.size(); ++i)
    s.max_dist = std::max(s.max_dist, double((sb.m_nodes[i].m_x - com).length()));
  return s;
}

}  // namespace

std::string FemBallModelConfig::Validate() const {
  if (!(courant > 0 && courant <= 10)) return "courant factor must be in (0, 10]";
  if (!(max_time_step_s > 0 && max_time_step_s <= 0.01)) return "max time step must be in (0, 0.01] s";
  if (!(time_step_s >= 0 && time_step_s <= 0.01)) return "time step must be in [0, 0.01] s";
  if (!(gravity_mps2 > 0)) return "gravity must be > 0";
  if (!(margin_per_radius > 0 && margin_per_radius < 1)) return "margin must be in (0, 1) radius";
  if (!(sdf_voxel_per_radius > 0)) return "SDF voxel must be > 0";
  if (!(contact_erp >= 0 && contact_erp <= 1)) return "contact erp must be in [0, 1]";
  if (!(camera_rate_hz > 0)) return "camera rate must be > 0";
  if (apex_window_frames < 1) return "apex window must be >= 1 frame";
  if (!(max_wall_time_s > 0)) return "max wall time must be > 0";
  return {};
}

FemBallModel::FemBallModel(BallPreset ball, FemBallModelConfig config)
    : ball_(std::move(ball)), config_(std::move(config)) {
  if (const std::string err = config_.Validate(); !err.empty()) throw std::invalid_argument(err);
  if (!(ball_.diameter_m > 0) || !(ball_.mass_kg > 0))
    throw std::invalid_argument("ball '" + ball_.name + "' needs a diameter and a mass > 0");
}

std::vector<CoefficientSpec> FemBallModel::Coefficients() const { return Specs(ball_); }

CoefficientValues FemBallModel::Complete(const CoefficientValues& values, std::string* error) const {
  error->clear();
  const std::vector<CoefficientSpec> specs = Specs(ball_);
  CoefficientValues out;
  for (const auto& s : specs) out[s.name] = s.default_value;
  for (const auto& [name, value] : values) {
    const auto it = std::find_if(specs.begin(), specs.end(),
                                 [&](const CoefficientSpec& s) { return s.name == name; });
    if (it == specs.end()) {
      *error = "unknown coefficient '" + name + "' for bullet-fem (see simulate --list-coeffs)";
      return {};
    }
    const double v = it->discrete ? std::round(value) : value;
    if (!std::isfinite(v) || v < it->lower || v > it->upper) {
      *error = fmt::format("coefficient {} = {:.6g} is outside [{:.4g}, {:.4g}]", name, value, it->lower, it->upper);
      return {};
    }
    out[name] = v;
  }
  return out;
}

std::shared_ptr<const TetMesh> FemBallModel::Mesh(const CoefficientValues& values) const {
  std::string error;
  const CoefficientValues all = Complete(values, &error);
  if (!error.empty()) throw std::invalid_argument(error);
  return GetTetMesh(Coeffs::From(all).mesh, config_.tetgen);
}

double FemBallModel::TimeStep(const CoefficientValues& values, double* crossing_time_s) const {
  std::string error;
  const CoefficientValues all = Complete(values, &error);
  if (!error.empty()) throw std::invalid_argument(error);
  const Coeffs c = Coeffs::From(all);
  const auto mesh = GetTetMesh(c.mesh, config_.tetgen);
  const double r = ball_.radius_m();
  const double density = ball_.mass_kg / (MeshVolume(*mesh) * r * r * r);
  const double wave_speed = std::sqrt((c.Lambda() + 2 * c.Mu()) / density);
  const double crossing = MinAltitude(*mesh) * r / wave_speed;
  if (crossing_time_s) *crossing_time_s = crossing;
  if (config_.time_step_s > 0) return config_.time_step_s;
  return std::min(config_.max_time_step_s, config_.courant * crossing);
}

SimulationResult FemBallModel::Simulate(const CoefficientValues& values,
                                        const SimulationOptions& options) const {
  const auto wall_start = std::chrono::steady_clock::now();
  SimulationResult result;
  auto finish = [&](std::string failure) {
    result.ok = failure.empty();
    result.failure = std::move(failure);
    result.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return result;
  };
  if (const std::string invalid = SimulationOptionsError(options); !invalid.empty())
    return finish(invalid);

  std::string error;
  const CoefficientValues all = Complete(values, &error);
  if (!error.empty()) return finish(error);
  const Coeffs c = Coeffs::From(all);
  std::shared_ptr<const TetMesh> mesh;
  double dt = 0;
  try {
    mesh = GetTetMesh(c.mesh, config_.tetgen);
    dt = TimeStep(all);
  } catch (const std::exception& e) {
    return finish(e.what());
  }

  World w;
  const double rest_width_height = BuildWorld(ball_, config_, c, *mesh, options.drop_height_m, &w);
  btSoftBody& sb = *w.ball;

  const double r = ball_.radius_m(), g = config_.gravity_mps2;
  const double y0 = options.drop_height_m + r;
  const double energy0 = g * y0;
  const double energy_slack = 0.02 * energy0 + g * 0.05 * r;
  const double v_max = 3 * std::sqrt(2 * g * y0) + 1;
  // Air drag on the centre, spread over the nodes as one velocity change (the deformable
  // solver has no aerodynamics of its own): dv = -k |v| v dt, k = Cd rho pi r^2 / (2 m).
  const double drag_k = c.drag * config_.air_density_kgpm3 * kPi * r * r / (2 * ball_.mass_kg);
  auto at = [](double t) { return fmt::format(" at t={:.4g} s", t); };

  std::vector<double> cam_t, cam_y;
  long next_cam = 0, next_traj = 0, last_impact = -1;
  double rest_since = -1, prev_t = 0, prev_bottom = 0;
  const long total_steps = static_cast<long>(std::ceil(options.duration_s / dt - 1e-9));

  for (long step = 0;; ++step) {
    const double t = double(step) * dt;
    const State s = Measure(sb);
    if (!s.finite) return finish("diverged (NaN)" + at(t));
    if (s.min_y < -r) return finish(fmt::format("diverged (a node {:.3g} m below the floor){}", -s.min_y, at(t)));
    if (s.com_y < 0) return finish("diverged (ball through the floor)" + at(t));
    if (s.max_dist > 3 * r)
      return finish(fmt::format("diverged (explosion: a node {:.3g} radii from the centre){}", s.max_dist / r, at(t)));
    if (s.max_speed > v_max) return finish(fmt::format("diverged (a node at {:.3g} m/s){}", s.max_speed, at(t)));
    const double energy =
        0.5 * (s.com_vx * s.com_vx + s.com_vy * s.com_vy + s.com_vz * s.com_vz) + g * s.com_y;
    if (energy > energy0 + energy_slack)
      return finish(fmt::format("diverged (energy growth: {:.4g}x the release energy){}", energy / energy0, at(t)));

    // Camera samples at exact frame times, interpolated between the steps around them.
    const double bottom = s.com_y - r;
    bool arc_below = false;
    while (double(next_cam) / config_.camera_rate_hz <= t + 1e-12) {
      const double tc = double(next_cam) / config_.camera_rate_hz;
      const double f = step == 0 ? 1 : (tc - prev_t) / (t - prev_t);
      cam_t.push_back(tc);
      cam_y.push_back(prev_bottom + f * (bottom - prev_bottom));
      ++next_cam;
      const size_t n = cam_y.size();
      if (n >= 3 && cam_y[n - 2] < cam_y[n - 3] && cam_y[n - 2] <= cam_y[n - 1]) {
        if (last_impact >= 0 &&
            *std::max_element(cam_y.begin() + last_impact, cam_y.end()) < options.min_bounce_height_m)
          arc_below = true;
        last_impact = static_cast<long>(n - 2);
      }
      const double speed = std::sqrt(s.com_vx * s.com_vx + s.com_vy * s.com_vy + s.com_vz * s.com_vz);
      if (!(cam_y.back() < options.min_bounce_height_m && speed < 0.02)) rest_since = -1;
      else if (rest_since < 0) rest_since = tc;
      else if (tc - rest_since > 0.25) arc_below = true;
    }
    if (arc_below) break;
    prev_t = t;
    prev_bottom = bottom;
    if (options.record_trajectory &&
        double(next_traj) / options.trajectory_rate_hz <= t + 1e-12) {
      TrajectorySample ts;
      ts.t_s = t;
      ts.center_height_m = s.com_y;
      ts.bottom_height_m = s.min_y;
      const double height = s.max_y - s.min_y;
      ts.width_height_ratio = height > 0 ? (s.max_x - s.min_x) / height / rest_width_height : 1;
      result.trajectory.push_back(ts);
      while (double(next_traj) / options.trajectory_rate_hz <= t + 1e-12) ++next_traj;
    }
    if (step >= total_steps) break;
    if ((step & 255) == 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count() > config_.max_wall_time_s)
      return finish(fmt::format("stopped: wall-time limit of {:.3g} s reached{}", config_.max_wall_time_s, at(t)));

    if (drag_k > 0) {
      const double speed = std::sqrt(s.com_vx * s.com_vx + s.com_vy * s.com_vy + s.com_vz * s.com_vz);
      const double f = -drag_k * speed * dt;
      const btVector3 dv(btScalar(f * s.com_vx), btScalar(f * s.com_vy), btScalar(f * s.com_vz));
      for (int i = 0; i < sb.m_nodes.size(); ++i) {
        sb.m_nodes[i].m_v += dv;
        sb.m_nodes[i].m_vn += dv;  // the implicit solve starts from m_vn
      }
    }
    w.world->stepSimulation(btScalar(dt), 0);
  }

  const MeasuredBounces mb = MeasureBounces(cam_t, cam_y, config_.apex_window_frames, 0);
  if (const std::string diverged = TakeMeasuredBounces(mb, options, &result); !diverged.empty())
    return finish(diverged);
  if (options.record_trajectory && result.trajectory.empty()) return finish("no trajectory samples");
  return finish({});
}

}  // namespace bouncefit
