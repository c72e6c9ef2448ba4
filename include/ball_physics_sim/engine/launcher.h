#pragma once

#include <string>

#include "ball_physics_sim/engine/ball.h"

namespace ball_physics_sim::engine {

// A cannon: fires balls of one kind from `position` along `angle` (rad, from +x toward +y).
struct Launcher {
  std::string name;
  Vec2 position = Vec2::Zero();
  double angle = 0.0;
  double speed = 5.0;  // default muzzle speed, m/s
  Ball projectile;     // radius, mass and restitution of what it fires

  Vec2 aimDirection() const;
  // The ball that leaves the muzzle at `speed` along the aim.
  Ball launch(double speed) const;
};

}  // namespace ball_physics_sim::engine
