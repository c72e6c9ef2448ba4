#pragma once

#include <optional>

#include "ball_physics_sim/engine/launcher.h"
#include "ball_physics_sim/engine/prediction.h"
#include "ball_physics_sim/engine/world.h"

namespace ball_physics_sim::engine {

// A launch angle and what the engine's prediction says the shot then does.
struct BankShot {
  double angle = 0.0;  // rad, from +x toward +y
  ShotPrediction prediction;  // its bounces, and the strike on the target as final_impact
};

// The most bounces a bank shot may take before it strikes.
constexpr int kMaxBankBounces = 3;

// A shot from `launcher` at `speed` that strikes ball `target` after 1 to `max_bounces`
// bounces off segments within `horizon` seconds, found by searching launch angles with
// predictShot. The angles are scanned all round on the world with only the target and the
// resting balls it leans on (cheap), finely enough that a stretch of angles striking the
// target spans several samples (up to a bound on the scan's work); each stretch's edges are
// then bisected and the shot aimed at its middle, the most forgiving aim. The best few
// stretches, by fewest bounces then earliest strike, are tried until one is confirmed on the
// whole world (where another ball may be in the way). None if there is no such ball or none
// of those is confirmed; throws std::invalid_argument as predictShot does.
std::optional<BankShot> aimBank(const World& world, const Launcher& launcher, double speed,
                                BallId target, double time_step, double horizon,
                                int max_bounces = kMaxBankBounces);

}  // namespace ball_physics_sim::engine
