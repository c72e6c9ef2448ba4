#pragma once

#include <optional>

#include "ball_physics_sim/engine/ball.h"
#include "ball_physics_sim/engine/motion.h"

namespace ball_physics_sim::engine {

// A launch direction and how long the ball then takes to reach its target.
struct AimSolution {
  double angle = 0.0;  // rad, from +x toward +y
  double time_of_flight = 0.0;
};

// The same direction as `angle`, in (-pi, pi].
double normalizedAngle(double angle);

// Straight at `target` at `speed` (a world without gravity). None if target == from.
std::optional<AimSolution> aimStraight(const Vec2& from, const Vec2& target, double speed);

// At `speed` under constant `gravity`, the launch whose parabola passes through `target`: of the
// two, the low arc (reaches it first) or the high one. None when the target is out of reach:
// in the frame where gravity points down, tan(theta) = (v^2 -+ sqrt(v^4 - g (g x^2 + 2 y v^2)))
// / (g x) has no real solution.
std::optional<AimSolution> aimBallistic(const Vec2& from, const Vec2& target, double speed,
                                        const Vec2& gravity, bool high_arc);

// The launch velocity whose ball reaches `target` exactly `time_of_flight` > 0 seconds later
// under `gravity`: from from + v t + g t^2 / 2 = target, v = (target - from) / t - g t / 2.
Vec2 launchVelocityFor(const Vec2& from, const Vec2& target, double time_of_flight,
                       const Vec2& gravity);

// At `speed` under `gravity`, the launch whose ball's centre meets, as early as possible, the
// centre of a ball moving with `target` (flying under gravity, rolling, or at rest). Seen from
// a point falling freely from the muzzle the target moves as D(t) = P + V t + (a - g) t^2 / 2
// and the shot flies straight at `speed`: the first t > 0 with |D(t)| = speed t, aimed along
// D(t). None when the target starts at `from` or no shot at this speed ever catches it.
std::optional<AimSolution> aimLeading(const Vec2& from, double speed, const Motion& target,
                                      const Vec2& gravity);

// A shot fired after `delay` seconds, reaching its target `time_of_flight` later.
struct TimedShot {
  double delay = 0.0;
  double time_of_flight = 0.0;
};

// With the aim fixed along `angle` at `speed` under `gravity`: the shortest delay >= 0 after
// which a shot meets, centre on centre, a ball moving with `target`. The shot's path is fixed,
// so the target must cross it at the moment the shot is there: with x across gravity and y
// against it (or along the shot when there is none), x_target(s) = u_x t fixes the time of
// flight t of a target time s, and y_target(s) = u_y t - g t^2 / 2 is then a quartic in s; the
// delay is s - t. None when the target never crosses the path in time.
std::optional<TimedShot> timeShot(const Vec2& from, double angle, double speed,
                                  const Motion& target, const Vec2& gravity);

// The least launch speed that reaches `target` under `gravity`: v^2 = g (y + |d|), with y the
// target's height above the launch point and |d| its distance.
double minimumBallisticSpeed(const Vec2& from, const Vec2& target, const Vec2& gravity);

}  // namespace ball_physics_sim::engine
