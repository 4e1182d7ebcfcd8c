#pragma once
// The fitted ball in your own Bullet world (Bullet 3.24, classic btSoftBody): the same mesh,
// configuration and rebound boost the fit ran with (model/soft_ball_world.h is bouncefit's
// own simulation, shipped verbatim).
//
//   btSoftRigidDynamicsWorld world(...);          // your world, your floor
//   btSoftBody* ball = fitted_ball::AddFittedBall(world, btVector3(0, 1.02, 0));
//   for (;;) world.stepSimulation(fitted_ball::kTimeStep, 0);   // one fixed step per call
//
// The coefficients hold for that fixed step and fitted_ball::Config()'s iterations only.
// What the fit's floor was: a static box, friction fitted_ball::Ball().values
// .at("floor_friction"), its top face a collision margin (fitted_ball::Config()
// .margin_per_radius x the radius) below the surface the ball's mesh touches.
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include "model/soft_ball_world.h"

namespace fitted_ball {

// The fixed settings and the ball as fitted (fitted_ball_data.cc).
bouncefit::SoftBallWorldConfig Config();
bouncefit::SoftBallSpec Ball();
// One line: the ball, the fit and its residual.
const char* Summary();

// Adds the fitted ball to `world`, its centre at `centre`, ready to drop: it is made above
// the origin, settled there (your world is stepped Config().settle_time_s with soft-body
// gravity off: add the ball before your moving bodies) and moved to `centre`. Sets the
// world's soft-body info (gravity, air density, SDF voxel) and its internal pre-tick
// callback: the rebound boost (a world has one such callback; with several balls or a
// callback of your own, call bouncefit::ReboundBoost::BeforeStep from yours instead).
// The ball belongs to the world's owner; the boost lives as long as the program.
btSoftBody* AddFittedBall(btSoftRigidDynamicsWorld& world, btVector3 centre);

// Step your world with world.stepSimulation(kTimeStep, 0) (seconds).
extern const btScalar kTimeStep;

}  // namespace fitted_ball
