#include "ball_physics_sim/engine/launcher.h"

#include <cmath>

namespace ball_physics_sim::engine {

Vec2 Launcher::aimDirection() const { return Vec2(std::cos(angle), std::sin(angle)); }

Ball Launcher::launch(double speed) const {
  Ball ball = projectile;
  ball.position = position;
  ball.velocity = speed * aimDirection();
  return ball;
}

}  // namespace ball_physics_sim::engine
