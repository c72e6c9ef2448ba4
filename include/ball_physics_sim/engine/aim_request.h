#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/launcher.h"
#include "ball_physics_sim/engine/world.h"

namespace ball_physics_sim::engine {

// The longest flight an aim confirms with the prediction, and the furthest a caller should
// predict: a prediction runs the whole world, so a longer look costs proportionally more.
constexpr double kMaxPredictionHorizon = 60.0;  // s

// How a launcher is aimed; the values are those of the node's Aim service.
enum class AimMode : std::uint8_t {
  kAngle = 0,            // along `angle`
  kTarget = 1,           // straight at `target`
  kTargetBallistic = 2,  // under gravity, the arc through `target`
  kLeadBall = 3,         // strike the moving ball `target_ball` as early as possible
  kTimed = 4,            // along `angle`: when to fire to strike ball `target_ball`
  kBank = 5,             // strike ball `target_ball` after 1 to kMaxBankBounces bounces
};

// What is asked of a launcher. A mode outside AimMode is refused, naming the modes.
struct AimRequest {
  AimMode mode = AimMode::kAngle;
  double angle = 0.0;           // rad, from +x toward +y (kAngle, kTimed)
  Vec2 target = Vec2::Zero();   // kTarget, kTargetBallistic
  BallId target_ball = 0;       // kLeadBall, kTimed, kBank
  double speed = 0.0;           // m/s; 0: the launcher's own
  bool high_arc = false;        // kTargetBallistic at `speed`: the high arc of the two
  // s, kTargetBallistic only: arrive this long after firing, at the speed that takes (leave
  // `speed` 0); 0: at `speed`.
  double time_of_flight = 0.0;
};

// The caller's step and limits. Refusals name them as the node's parameters that set them
// (~max_speed, ~prediction_horizon), so that a user of the node knows what to change.
struct AimLimits {
  double time_step = 1.0 / 60.0;  // s: shots are predicted, and TIMED's delay counted, in it
  // s: how far kAngle's first impact is looked for and kBank searches; 0: no predictions, so
  // nothing is checked for obstacles and kBank is refused.
  double prediction_horizon = 0.0;
  double max_speed = 0.0;  // m/s, the fastest shot
  // m: a shot that strikes a body within this of `target` has arrived there (a point clicked
  // on a segment drawn thicker than it is).
  double target_tolerance = 0.0;
};

// A confirmed aim, or a refusal: what the launcher should be set to, and why or why not.
struct AimAnswer {
  std::optional<AimSolution> solution;  // none: refused, for the reason in `message`
  double speed = 0.0;                   // m/s, the shot's (a time of flight sets it)
  double fire_after = 0.0;              // s, kTimed: fire after this many whole time steps
  // The shot's centre where it arrives or first strikes, when that is known; a TARGET aim
  // refused as blocked keeps the target it checked.
  std::optional<Vec2> predicted_hit;
  std::string message;  // what the shot does, or what is wrong with the request
};

// Aims `launcher` in `world` as `request` asks, confirming with the engine's prediction that
// the shot arrives unblocked (or strikes the ball asked for). Fixed-angle aims (kAngle, and
// kTarget under gravity, which only points) are kept even when the muzzle is blocked.
AimAnswer aimLauncher(const World& world, const Launcher& launcher, const AimRequest& request,
                      const AimLimits& limits);

// The speed `requested` asks for (0: the launcher's own), or none with `error` saying why.
std::optional<double> shotSpeed(double requested, const Launcher& launcher, double max_speed,
                                std::string& error);

}  // namespace ball_physics_sim::engine
