// Compiled into an exported fitted_ball project by tests/fit_export_project_slow_test.cc: a
// user's own world (their floor, their step loop) with the ball from fitted_ball.h; prints
// the bounce heights from argv[1] metres as fitted_ball does.
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fitted_ball.h"

int main(int argc, char** argv) {
  const double drop = argc > 1 ? std::atof(argv[1]) : 1.0;
  const auto cfg = fitted_ball::Config();
  const auto ball = fitted_ball::Ball();
  const double r = ball.radius_m;
  btSoftBodyRigidBodyCollisionConfiguration collision;
  btCollisionDispatcher dispatcher(&collision);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &collision);
  world.setGravity(btVector3(0, -9.81f, 0));
  // The floor: its top face one collision margin below y = 0 (fitted_ball.h).
  btBoxShape floor_shape(btVector3(2, 0.5, 2));
  btTransform at;
  at.setIdentity();
  at.setOrigin(btVector3(0, btScalar(-0.5 - cfg.margin_per_radius * r), 0));
  btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, &floor_shape);
  ci.m_startWorldTransform = at;
  ci.m_friction = btScalar(ball.values.at("floor_friction"));
  btRigidBody floor(ci);
  world.addRigidBody(&floor);

  btSoftBody* sb = fitted_ball::AddFittedBall(world, btVector3(0, btScalar(drop + r), 0));
  std::vector<double> t, y;
  const long steps = std::lround(4.0 / cfg.time_step_s);
  for (long i = 0; i <= steps; ++i) {
    if (i % 4 == 0) {
      double cy = 0;
      for (int k = 0; k < sb->m_nodes.size(); ++k) cy += sb->m_nodes[k].m_x.y();
      t.push_back(i * cfg.time_step_s);
      y.push_back(cy / sb->m_nodes.size() - r);
    }
    world.stepSimulation(fitted_ball::kTimeStep, 0);
  }
  for (double h : bouncefit::MeasureBounces(t, y, cfg.apex_window_frames).apex_heights_m)
    if (h > 0.01) std::printf("%.9f\n", h);
  world.removeSoftBody(sb);
  delete sb;
  world.removeRigidBody(&floor);
}
