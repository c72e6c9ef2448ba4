#pragma once

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/segment.h"

// Bodies for engine tests, with the defaults most tests want.
namespace ball_physics_sim::engine::test {

inline Ball ball(Vec2 position, Vec2 velocity, double radius = 0.5, double mass = 1.0,
                 double restitution = 1.0) {
  Ball b;
  b.position = position;
  b.velocity = velocity;
  b.radius = radius;
  b.mass = mass;
  b.restitution = restitution;
  return b;
}

inline Segment segment(Vec2 start, Vec2 end, double restitution = 1.0) {
  Segment s;
  s.start = start;
  s.end = end;
  s.restitution = restitution;
  return s;
}

}  // namespace ball_physics_sim::engine::test
