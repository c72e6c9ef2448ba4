#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/segment.h"
#include "ball_physics_sim/engine/world.h"

// Bodies for engine tests, with the defaults most tests want, and a way to run their worlds.
namespace ball_physics_sim::engine::test {

constexpr double kG = 9.81;               // m/s^2, standard gravity
constexpr double kFrameStep = 1.0 / 60.0;  // s, the node's usual step

// The message `check` throws, or "no error".
template <typename Check>
std::string refusal(Check check) {
  try {
    check();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

// Steps `world` through `seconds` in whole steps of `dt`.
inline void run(World& world, double seconds, double dt = kFrameStep) {
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int i = 0; i < steps; ++i) world.step(dt);
}

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

// Four walls of `restitution` round `centre`, `half` from it.
inline void addBox(World& world, double half, const Vec2& centre = Vec2::Zero(),
                   double restitution = 1.0) {
  const Vec2 corners[] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  for (int k = 0; k < 4; ++k)
    world.addSegment(
        segment(centre + corners[k], centre + corners[(k + 1) % 4], restitution));
}

}  // namespace ball_physics_sim::engine::test
