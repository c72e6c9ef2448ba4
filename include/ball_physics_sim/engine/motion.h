#pragma once

#include "ball_physics_sim/engine/ball.h"

namespace ball_physics_sim::engine {

// Motion under constant acceleration, exact at every time: p(t) = p + v t + a t^2 / 2.
// Also serves for the motion of one body relative to another.
struct Motion {
  Vec2 position = Vec2::Zero();
  Vec2 velocity = Vec2::Zero();
  Vec2 acceleration = Vec2::Zero();

  Vec2 positionAt(double t) const { return position + t * (velocity + 0.5 * t * acceleration); }
  Vec2 velocityAt(double t) const { return velocity + t * acceleration; }
  Motion relativeTo(const Motion& other) const {
    return {position - other.position, velocity - other.velocity, acceleration - other.acceleration};
  }
};

}  // namespace ball_physics_sim::engine
