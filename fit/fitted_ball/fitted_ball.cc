#include "fitted_ball.h"

#include <memory>
#include <vector>

namespace fitted_ball {

const btScalar kTimeStep = btScalar(Config().time_step_s);

btSoftBody* AddFittedBall(btSoftRigidDynamicsWorld& world, btVector3 centre) {
  const bouncefit::SoftBallWorldConfig cfg = Config();
  static const bouncefit::SoftBallSpec ball = Ball();
  btSoftBodyWorldInfo& info = world.getWorldInfo();
  bouncefit::ConfigureSoftBallWorldInfo(cfg, ball.radius_m, &info);
  btSoftBody* body = bouncefit::CreateSoftBall(cfg, ball, &info, double(centre.y()) - ball.radius_m);
  world.addSoftBody(body);
  bouncefit::SettleSoftBall(cfg, double(centre.y()), &world, &info, body);
  // Moved sideways node by node (btSoftBody::translate would take the settled shape as rest).
  for (int i = 0; i < body->m_nodes.size(); ++i) {
    body->m_nodes[i].m_x += btVector3(centre.x(), 0, centre.z());
    body->m_nodes[i].m_q = body->m_nodes[i].m_x;
  }
  static std::vector<std::unique_ptr<bouncefit::ReboundBoost>> boosts;
  boosts.push_back(std::make_unique<bouncefit::ReboundBoost>(cfg, ball.values));
  if (boosts.back()->active()) boosts.back()->Attach(&world, body);
  return body;
}

}  // namespace fitted_ball
