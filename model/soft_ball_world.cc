#include "model/soft_ball_world.h"

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace bouncefit {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The coefficients Bullet is given (the rebound boost reads its own, ReboundBoost).
struct Coeffs {
  double kLST, kAST, kVST, pressure, kDP, kDG, kLF, kSR, kSK, kSS;
  double volume_conservation, kKHR, floor_friction, floor_restitution;

  static Coeffs From(const CoefficientValues& v) {
    Coeffs c;
    c.kLST = v.at("linear_stiffness");
    c.kAST = v.at("angular_stiffness");
    c.kVST = v.at("volume_stiffness");
    c.pressure = v.at("pressure");
    c.kDP = v.at("damping");
    c.kDG = v.at("drag");
    c.kLF = v.at("lift");
    c.kSR = v.at("soft_rigid_impulse_split");
    c.kSK = v.at("soft_kinetic_impulse_split");
    c.kSS = v.at("soft_soft_impulse_split");
    c.volume_conservation = v.at("volume_conservation");
    c.kKHR = v.at("contact_hardness");
    c.floor_friction = v.at("floor_friction");
    c.floor_restitution = v.at("floor_restitution");
    return c;
  }
};

// One Bullet world with the floor and the ball, torn down in the right order.
struct World {
  btSoftBodyWorldInfo info;
  std::unique_ptr<btSoftBodyRigidBodyCollisionConfiguration> collision_config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver;
  std::unique_ptr<btSoftRigidDynamicsWorld> world;
  std::unique_ptr<btBoxShape> floor_shape;
  std::unique_ptr<btRigidBody> floor;
  std::unique_ptr<btSoftBody> ball;

  ~World() {
    if (world && ball) world->removeSoftBody(ball.get());
    if (world && floor) world->removeRigidBody(floor.get());
    ball.reset();
    floor.reset();
    world.reset();
    info.m_sparsesdf.Reset();
  }
};

// Rotation taking unit vector a onto unit vector b (Rodrigues), as a row-major 3x3.
std::array<double, 9> RotationOnto(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const std::array<double, 3> v{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                                a[0] * b[1] - a[1] * b[0]};
  const double c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  std::array<double, 9> r{1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (c < -1 + 1e-12) return {1, 0, 0, 0, -1, 0, 0, 0, -1};  // a = -b (only ever +-y here)
  const double k = 1 / (1 + c);
  const double vx[9] = {0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double vx2 = 0;
      for (int m = 0; m < 3; ++m) vx2 += vx[i * 3 + m] * vx[m * 3 + j];
      r[static_cast<size_t>(i * 3 + j)] += vx[i * 3 + j] + vx2 * k;
    }
  return r;
}

// The world of one run: gravity, the soft-body world info, and the floor: a big box (SDF
// contact works against convex shapes only) whose top face is at y = -margin, so the ball's
// mesh surface touches y = 0 when its skin touches the floor.
void BuildWorld(const SoftBallWorldConfig& cfg, double r, const Coeffs& c, World* w) {
  const double margin = cfg.margin_per_radius * r;
  w->collision_config = std::make_unique<btSoftBodyRigidBodyCollisionConfiguration>();
  w->dispatcher = std::make_unique<btCollisionDispatcher>(w->collision_config.get());
  w->broadphase = std::make_unique<btDbvtBroadphase>();
  w->solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  w->world = std::make_unique<btSoftRigidDynamicsWorld>(w->dispatcher.get(), w->broadphase.get(),
                                                        w->solver.get(), w->collision_config.get());
  w->world->setGravity(btVector3(0, -btScalar(cfg.gravity_mps2), 0));
  w->info.m_broadphase = w->broadphase.get();
  w->info.m_dispatcher = w->dispatcher.get();
  w->info.m_sparsesdf.Initialize();
  ConfigureSoftBallWorldInfo(cfg, r, &w->info);

  const btScalar half_size = btScalar(std::max(2.0, 20 * r));
  const btScalar half_thickness = btScalar(std::max(0.5, 5 * r));
  w->floor_shape = std::make_unique<btBoxShape>(btVector3(half_size, half_thickness, half_size));
  btTransform floor_tr;
  floor_tr.setIdentity();
  floor_tr.setOrigin(btVector3(0, -half_thickness - btScalar(margin), 0));
  btRigidBody::btRigidBodyConstructionInfo floor_ci(0, nullptr, w->floor_shape.get());
  floor_ci.m_startWorldTransform = floor_tr;
  floor_ci.m_friction = btScalar(c.floor_friction);
  floor_ci.m_restitution = btScalar(c.floor_restitution);
  w->floor = std::make_unique<btRigidBody>(floor_ci);
  w->world->addRigidBody(w->floor.get());
}

}  // namespace

void ConfigureSoftBallWorldInfo(const SoftBallWorldConfig& cfg, double r, btSoftBodyWorldInfo* info) {
  info->m_gravity = btVector3(0, -btScalar(cfg.gravity_mps2), 0);  // what soft bodies use
  info->air_density = btScalar(cfg.air_density_kgpm3);
  info->water_density = 0;
  info->m_sparsesdf.setDefaultVoxelsz(btScalar(cfg.sdf_voxel_per_radius * r));
  info->m_sparsesdf.Reset();  // takes the voxel size
}

btSoftBody* CreateSoftBall(const SoftBallWorldConfig& cfg, const SoftBallSpec& ball,
                           btSoftBodyWorldInfo* info, double bottom_height_m, double turn_rad,
                           double* rest_width_height) {
  if (!ball.mesh.nodes || !ball.mesh.tetras || !ball.mesh.faces)
    throw std::invalid_argument("the ball has no mesh");
  const Coeffs c = Coeffs::From(ball.values);
  const double r = ball.radius_m;
  const double margin = cfg.margin_per_radius * r;
  // Ball: the unit-sphere mesh turned so that one surface vertex points straight down
  // (symmetric first contact), scaled to the radius, bottom at the drop height.
  const auto& nodes = *ball.mesh.nodes;
  const double t = (1 + std::sqrt(5.0)) / 2;
  const double n0 = std::sqrt(1 + t * t);
  const auto rot = RotationOnto({-1 / n0, t / n0, 0}, {0, -1, 0});
  const double turn_cos = std::cos(turn_rad), turn_sin = std::sin(turn_rad);
  std::vector<btVector3> x(nodes.size());
  double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
  for (size_t i = 0; i < nodes.size(); ++i) {
    double p[3];
    for (int a = 0; a < 3; ++a)
      p[a] = rot[static_cast<size_t>(a * 3)] * nodes[i][0] +
             rot[static_cast<size_t>(a * 3 + 1)] * nodes[i][1] +
             rot[static_cast<size_t>(a * 3 + 2)] * nodes[i][2];
    xmin = std::min(xmin, p[0]);
    xmax = std::max(xmax, p[0]);
    ymin = std::min(ymin, p[1]);
    ymax = std::max(ymax, p[1]);
    // Then turned about the vertical (release_turn_rad: the ensemble's perturbation).
    const double px = turn_cos * p[0] + turn_sin * p[2], pz = -turn_sin * p[0] + turn_cos * p[2];
    p[0] = px;
    p[2] = pz;
    x[i] = btVector3(btScalar(p[0] * r), btScalar(p[1] * r + r + bottom_height_m), btScalar(p[2] * r));
  }
  if (rest_width_height) *rest_width_height = (xmax - xmin) / (ymax - ymin);

  auto body = std::make_unique<btSoftBody>(info, static_cast<int>(x.size()), x.data(), nullptr);
  btSoftBody* sb = body.get();
  btSoftBody::Material* mat = sb->m_materials[0];
  mat->m_kLST = btScalar(c.kLST);
  mat->m_kAST = btScalar(c.kAST);
  mat->m_kVST = btScalar(c.kVST);
  // What btSoftBodyHelpers::CreateFromTetGenData does (tetras, their 6 edges as links),
  // without its printf and float parsing, plus the boundary faces it never appends.
  std::set<std::pair<int, int>> seen;
  for (const auto& tet : *ball.mesh.tetras) {
    sb->appendTetra(tet[0], tet[1], tet[2], tet[3]);
    const int e[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
    for (const auto& ed : e) {
      int a = tet[static_cast<size_t>(ed[0])], b = tet[static_cast<size_t>(ed[1])];
      if (seen.insert({std::min(a, b), std::max(a, b)}).second) sb->appendLink(a, b, nullptr, false);
    }
  }
  for (const auto& f : *ball.mesh.faces) sb->appendFace(f[0], f[1], f[2]);
  sb->setTotalMass(btScalar(ball.mass_kg), false);

  btSoftBody::Config& k = sb->m_cfg;
  const double m = ball.mass_kg, g = cfg.gravity_mps2;
  const double volume0 = 4.0 / 3.0 * kPi * r * r * r;
  k.kPR = btScalar(c.pressure * m * g * volume0 / (kPi * r * r));
  k.kVC = btScalar(c.volume_conservation * m * g / (kPi * r * r * volume0));
  k.kDP = btScalar(c.kDP);
  k.kDG = btScalar(c.kDG);
  k.kLF = btScalar(c.kLF);
  k.kSR_SPLT_CL = btScalar(c.kSR);
  k.kSK_SPLT_CL = btScalar(c.kSK);
  k.kSS_SPLT_CL = btScalar(c.kSS);
  k.kKHR = btScalar(c.kKHR);
  k.kDF = 1;
  k.aeromodel = btSoftBody::eAeroModel::V_TwoSidedLiftDrag;
  k.piterations = cfg.position_iterations;
  k.viterations = 0;
  k.diterations = 0;
  k.collisions = btSoftBody::fCollision::SDF_RS;
  sb->getCollisionShape()->setMargin(btScalar(margin));
  sb->setPose(true, false);  // rest volume for kVC
  sb->setActivationState(DISABLE_DEACTIVATION);
  if (!(sb->getVolume() > 0)) throw std::invalid_argument("the ball mesh encloses no volume");
  return body.release();
}

namespace {

struct NodeStats {
  bool finite = true;
  btVector3 com{0, 0, 0};
  btVector3 com_v{0, 0, 0};
  double min_y = 0, max_y = 0, min_x = 0, max_x = 0;
  double max_dist2 = 0;  // from the centre
  double max_speed2 = 0;
};

NodeStats Stats(const btSoftBody& sb) {
  NodeStats s;
  const int n = sb.m_nodes.size();
  double cx = 0, cy = 0, cz = 0, vx = 0, vy = 0, vz = 0;
  s.min_y = s.min_x = 1e300;
  s.max_y = s.max_x = -1e300;
  for (int i = 0; i < n; ++i) {
    const btVector3& x = sb.m_nodes[i].m_x;
    const btVector3& v = sb.m_nodes[i].m_v;
    cx += x.x();
    cy += x.y();
    cz += x.z();
    vx += v.x();
    vy += v.y();
    vz += v.z();
    s.min_y = std::min(s.min_y, double(x.y()));
    s.max_y = std::max(s.max_y, double(x.y()));
    s.min_x = std::min(s.min_x, double(x.x()));
    s.max_x = std::max(s.max_x, double(x.x()));
    s.max_speed2 = std::max(s.max_speed2, double(v.length2()));
  }
  if (!std::isfinite(cx + cy + cz + vx + vy + vz) || !std::isfinite(s.max_speed2)) {
    s.finite = false;
    return s;
  }
  s.com = btVector3(btScalar(cx / n), btScalar(cy / n), btScalar(cz / n));
  s.com_v = btVector3(btScalar(vx / n), btScalar(vy / n), btScalar(vz / n));
  for (int i = 0; i < n; ++i)
    s.max_dist2 = std::max(s.max_dist2, double((sb.m_nodes[i].m_x - s.com).length2()));
  return s;
}

// Stats(sb).com_v.y() to the bit (the same sum in the same order), without the rest.
double CentreVelocityY(const btSoftBody& sb) {
  const int n = sb.m_nodes.size();
  double vy = 0;
  for (int i = 0; i < n; ++i) vy += sb.m_nodes[i].m_v.y();
  return btScalar(vy / n);
}

}  // namespace

std::string SoftBallWorldConfig::Validate() const {
  if (!(time_step_s > 0 && time_step_s <= 0.01)) return "time step must be in (0, 0.01] s";
  if (position_iterations < 1 || position_iterations > 100) return "position iterations must be 1..100";
  if (!(gravity_mps2 > 0)) return "gravity must be > 0";
  if (!(margin_per_radius > 0 && margin_per_radius < 1)) return "margin must be in (0, 1) radius";
  if (!(sdf_voxel_per_radius > 0)) return "SDF voxel must be > 0";
  if (!(camera_rate_hz > 0)) return "camera rate must be > 0";
  if (apex_window_frames < 1) return "apex window must be >= 1 frame";
  if (!(max_wall_time_s > 0)) return "max wall time must be > 0";
  if (!(settle_time_s >= 0) || !(settle_damping >= 0 && settle_damping < 1))
    return "settle time must be >= 0 and settle damping in [0, 1)";
  return {};
}

void SettleSoftBall(const SoftBallWorldConfig& cfg, double centre_y, btSoftRigidDynamicsWorld* world,
                    btSoftBodyWorldInfo* info, btSoftBody* ball) {
  const long steps = std::lround(cfg.settle_time_s / cfg.time_step_s);
  if (steps <= 0) return;
  btSoftBody& sb = *ball;
  const btVector3 gravity = info->m_gravity;
  const btScalar damping = sb.m_cfg.kDP;
  info->m_gravity.setZero();
  sb.m_cfg.kDP = btScalar(cfg.settle_damping);
  for (long i = 0; i < steps; ++i) world->stepSimulation(btScalar(cfg.time_step_s), 0);
  info->m_gravity = gravity;
  sb.m_cfg.kDP = damping;
  btVector3 com(0, 0, 0);
  for (int i = 0; i < sb.m_nodes.size(); ++i) com += sb.m_nodes[i].m_x;
  com /= btScalar(sb.m_nodes.size());
  const btVector3 shift = btVector3(0, btScalar(centre_y), 0) - com;
  for (int i = 0; i < sb.m_nodes.size(); ++i) {
    btSoftBody::Node& n = sb.m_nodes[i];
    n.m_x += shift;
    n.m_q = n.m_x;
    n.m_v.setZero();
    n.m_f.setZero();
  }
}

ReboundLaw ReboundBoost::Law(const SoftBallWorldConfig& cfg, const CoefficientValues& values) {
  ReboundLaw law;
  law.boost = values.at("rebound_boost");
  law.boost_per_mps = values.at("rebound_boost_per_mps");
  law.restitution = values.at("rebound_restitution");
  law.restitution_per_mps = values.at("rebound_restitution_per_mps");
  law.gravity_mps2 = cfg.gravity_mps2;
  law.time_step_s = cfg.time_step_s;
  law.at_touch = cfg.rebound_at_touch;
  return law;
}

ReboundBoost::ReboundBoost(const SoftBallWorldConfig& cfg, const CoefficientValues& values)
    : time_step_s_(cfg.time_step_s), law_(Law(cfg, values)), contacts_(law_) {}

void ReboundBoost::Attach(btDynamicsWorld* world, btSoftBody* ball) {
  ball_ = ball;
  steps_ = 0;
  world->setInternalTickCallback(&ReboundBoost::Tick, this, /*isPreTick=*/true);
}

void ReboundBoost::Tick(btDynamicsWorld* world, btScalar) {
  auto* self = static_cast<ReboundBoost*>(world->getWorldUserInfo());
  self->BeforeStep(self->ball_, double(self->steps_) * self->time_step_s_);
  ++self->steps_;
}

// The contact episodes and the kick: model/rebound_kick.h.
void ReboundBoost::BeforeStep(btSoftBody* ball, double t) {
  double cy = 0, lowest = 1e30;
  for (int i = 0; i < ball->m_nodes.size(); ++i) {
    cy += ball->m_nodes[i].m_x.y();
    lowest = std::min(lowest, double(ball->m_nodes[i].m_x.y()));
  }
  cy /= std::max(1, ball->m_nodes.size());
  const double vy = CentreVelocityY(*ball);
  bool contact = ball->m_rcontacts.size() > 0;
  // The restitution law turns the ball as it touches: when the lowest node would pass the
  // floor within this step, not a step later from deep inside it (at 6 m/s a step is 13 mm,
  // two thirds of a ping-pong ball's radius, and the mesh caved in: measured from 2 m).
  const bool turns_at_touch = law_.restitution > 0 && law_.at_touch;
  if (turns_at_touch && vy < 0 && lowest + vy * time_step_s_ <= 0) contact = true;
  const double kick = contacts_.Step(t, contact, cy, vy, lowest);
  if (const double shift = contacts_.shift(); shift > 0)
    for (int i = 0; i < ball->m_nodes.size(); ++i) {  // onto the floor as it turns, and so on
      ball->m_nodes[i].m_x.setY(ball->m_nodes[i].m_x.y() - btScalar(shift));
      ball->m_nodes[i].m_q.setY(ball->m_nodes[i].m_q.y() - btScalar(shift));
    }
  if (kick != 0) ball->addVelocity(btVector3(0, btScalar(kick), 0));
}

SimulationResult SimulateSoftBallDrop(const SoftBallWorldConfig& cfg, const SoftBallSpec& ball,
                                      const SimulationOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  SimulationResult result;
  auto finish = [&](std::string failure) {
    result.ok = failure.empty();
    result.failure = std::move(failure);
    result.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return result;
  };
  if (const std::string invalid = cfg.Validate(); !invalid.empty()) return finish(invalid);
  if (const std::string invalid = SimulationOptionsError(options); !invalid.empty())
    return finish(invalid);
  if (!(ball.radius_m > 0) || !(ball.mass_kg > 0)) return finish("the ball needs a radius and a mass > 0");

  World w;
  double rest_width_height = 1;  // x extent / y extent of the undeformed mesh
  ReboundBoost boost(cfg, ball.values);
  try {
    BuildWorld(cfg, ball.radius_m, Coeffs::From(ball.values), &w);
    w.ball.reset(CreateSoftBall(cfg, ball, &w.info, options.drop_height_m, options.release_turn_rad,
                                &rest_width_height));
  } catch (const std::exception& e) {  // a mesh with no volume, a coefficient missing
    return finish(e.what());
  }
  w.world->addSoftBody(w.ball.get());
  btSoftBody& sb = *w.ball;
  // The surface's vertices (the nodes its faces use), renumbered from 0.
  std::vector<int> surface_nodes;
  if (options.record_trajectory && options.record_surface) {
    std::vector<int> index_of(ball.mesh.nodes->size(), -1);
    for (const auto& f : *ball.mesh.faces) {
      std::array<int, 3> tri{};
      for (size_t a = 0; a < 3; ++a) {
        int& index = index_of[static_cast<size_t>(f[a])];
        if (index < 0) {
          index = static_cast<int>(surface_nodes.size());
          surface_nodes.push_back(f[a]);
        }
        tri[a] = index;
      }
      result.surface.triangles.push_back(tri);
    }
  }
  SettleSoftBall(cfg, options.drop_height_m + ball.radius_m, w.world.get(), &w.info, &sb);
  // The rebound boost runs inside stepSimulation from here on, as in a user's world.
  // Always: it also times the impacts (a kick of 0 changes nothing).
  boost.Attach(w.world.get(), &sb);

  const double r = ball.radius_m;
  const double g = cfg.gravity_mps2;
  const double dt = cfg.time_step_s;
  const long total_steps = static_cast<long>(std::ceil(options.duration_s / dt - 1e-9));
  const double y0 = options.drop_height_m + r;  // centre at release
  const double energy0 = g * y0;                // per unit mass, at rest at release
  const double energy_slack = 0.02 * energy0 + g * 0.05 * r;
  const double v_max = 3 * std::sqrt(2 * g * y0) + 1;
  const double volume0 = sb.getVolume();
  // Why the run ends early, and when: written with a stream, as this file ships verbatim in the
  // exported fitted_ball project, which builds with Bullet and the C++17 standard library only.
  auto stop = [&](double t, const auto&... parts) {
    std::ostringstream m;
    m.precision(4);
    (m << ... << parts) << " at t=" << t << " s";
    return finish(m.str());
  };

  // Camera samples (the bounce measurement) and trajectory samples: the step nearest to
  // each sample time.
  std::vector<double> cam_t, cam_y;
  long next_cam = 0, next_traj = 0;
  auto step_of = [&](long j, double rate) { return std::lround(double(j) / rate / dt); };
  // Impacts found so far in the camera samples (local minima), for the early stop.
  long last_impact = -1;
  int impacts = 0;
  double rest_since = -1;

  for (long step = 0;; ++step) {
    const double t = double(step) * dt;
    result.simulated_time_s = t;
    const NodeStats s = Stats(sb);
    if (!s.finite) return stop(t, "diverged (NaN)");
    const double cy = s.com.y();
    if (s.min_y < -r) return stop(t, "diverged (a node ", -s.min_y, " m below the floor)");
    if (cy < 0) return stop(t, "diverged (ball through the floor)");
    if (s.max_dist2 > 9 * r * r)
      return stop(t, "diverged (explosion: a node ", std::sqrt(s.max_dist2) / r, " radii from the centre)");
    if (s.max_speed2 > v_max * v_max)
      return stop(t, "diverged (a node at ", std::sqrt(s.max_speed2), " m/s)");
    const double energy = 0.5 * double(s.com_v.length2()) + g * cy;
    if (energy > energy0 + energy_slack)
      return stop(t, "diverged (energy growth: ", energy / energy0, "x the release energy)");

    const double bottom = cy - r;
    if (step == step_of(next_cam, cfg.camera_rate_hz)) {
      const double volume = sb.getVolume();
      if (!(volume > 0.1 * volume0) || !(volume < 4 * volume0))
        return stop(t, "diverged (volume ", volume / volume0, "x the rest volume)");
      cam_t.push_back(t);
      cam_y.push_back(bottom);
      ++next_cam;
      // Early stop: an arc just closed whose top is below the bounces of interest, or the
      // ball lies still on the floor.
      const size_t n = cam_y.size();
      if (n >= 3 && cam_y[n - 2] < cam_y[n - 3] && cam_y[n - 2] <= cam_y[n - 1]) {
        if (last_impact >= 0) {
          const double top = *std::max_element(cam_y.begin() + last_impact, cam_y.end());
          if (top < options.min_bounce_height_m) break;
        }
        last_impact = static_cast<long>(n - 2);
        // Impact k + 1 closes bounce k's arc: the bounces asked for are all measured.
        if (options.max_bounces > 0 && ++impacts > options.max_bounces) break;
      }
      const bool still = bottom < options.min_bounce_height_m && s.com_v.length() < 0.02;
      if (!still) rest_since = -1;
      else if (rest_since < 0) rest_since = t;
      else if (t - rest_since > 0.25) break;
    }
    if (options.record_trajectory && step == step_of(next_traj, options.trajectory_rate_hz)) {
      TrajectorySample ts;
      ts.t_s = t;
      ts.center_height_m = cy;
      ts.bottom_height_m = s.min_y;  // the mesh's lowest point (deformed, sagging, ...)
      const double height = s.max_y - s.min_y;
      ts.width_height_ratio = height > 0 ? (s.max_x - s.min_x) / height / rest_width_height : 1;
      result.trajectory.push_back(ts);
      if (!surface_nodes.empty()) {
        std::vector<std::array<float, 3>> at_t(surface_nodes.size());
        for (size_t i = 0; i < surface_nodes.size(); ++i) {
          const btVector3& x = sb.m_nodes[surface_nodes[i]].m_x;
          at_t[i] = {float(x.x()), float(x.y()), float(x.z())};
        }
        result.surface.positions_m.push_back(std::move(at_t));
      }
      ++next_traj;
    }
    if (step >= total_steps) break;
    if ((step & 127) == 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count() > cfg.max_wall_time_s)
      return stop(t, "stopped: wall-time limit of ", cfg.max_wall_time_s, " s reached");

    w.world->stepSimulation(btScalar(dt), 0);
  }

  const MeasuredBounces mb = MeasureBounces(cam_t, cam_y, cfg.apex_window_frames, 0);
  if (const std::string diverged = TakeMeasuredBounces(mb, options, &result); !diverged.empty())
    return finish(diverged);
  result.impact_times_s = boost.ImpactTimes();  // to the step, not the camera frame
  if (options.record_trajectory && result.trajectory.empty())
    return finish("no trajectory samples");
  return finish({});
}

}  // namespace bouncefit
