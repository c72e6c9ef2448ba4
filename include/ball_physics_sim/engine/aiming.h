#pragma once

#include <optional>

#include "ball_physics_sim/engine/ball.h"

namespace ball_physics_sim::engine {

// A launch direction and how long the ball then takes to reach its target.
struct AimSolution {
  double angle = 0.0;  // rad, from +x toward +y
  double time_of_flight = 0.0;
};

// Straight at `target` at `speed` (a world without gravity). None if target == from.
std::optional<AimSolution> aimStraight(const Vec2& from, const Vec2& target, double speed);

// At `speed` under constant `gravity`, the launch whose parabola passes through `target`: of the
// two, the low arc (reaches it first) or the high one. None when the target is out of reach:
// in the frame where gravity points down, tan(theta) = (v^2 -+ sqrt(v^4 - g (g x^2 + 2 y v^2)))
// / (g x) has no real solution.
std::optional<AimSolution> aimBallistic(const Vec2& from, const Vec2& target, double speed,
                                        const Vec2& gravity, bool high_arc);

// The least launch speed that reaches `target` under `gravity`: v^2 = g (y + |d|), with y the
// target's height above the launch point and |d| its distance.
double minimumBallisticSpeed(const Vec2& from, const Vec2& target, const Vec2& gravity);

}  // namespace ball_physics_sim::engine
