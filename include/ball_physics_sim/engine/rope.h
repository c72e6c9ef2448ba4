#pragma once

#include <cstdint>
#include <optional>

#include "ball_physics_sim/engine/ball.h"

namespace ball_physics_sim::engine {

using RopeId = std::uint32_t;

// A rope ties a ball to a fixed anchor or to another ball and keeps their centres at most
// `length` apart. Slack, it does nothing; taut, it pulls along itself as hard as it must: a
// contact on the inside of a circle, held by the same normal forces as a resting contact. It
// goes taut as an impact with `restitution` (0: the jerk stops the ball's outward motion).
struct Rope {
  RopeId id = 0;
  BallId ball = 0;
  std::optional<BallId> other_ball;  // none: tied to `anchor`
  Vec2 anchor = Vec2::Zero();
  double length = 1.0;  // m
  double restitution = 0.0;
};

// Throws std::invalid_argument naming what is wrong: a ball tied to itself, a length not
// finite and > 0 or beyond kMaxCoordinate, a restitution outside [0, 1], an anchor not finite
// or beyond kMaxCoordinate.
void checkRope(const Rope& rope);

}  // namespace ball_physics_sim::engine
