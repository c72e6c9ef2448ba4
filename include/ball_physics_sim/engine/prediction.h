#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "ball_physics_sim/engine/world.h"

namespace ball_physics_sim::engine {

// What a shot hits first.
struct PredictedImpact {
  double time = 0.0;               // s after firing
  Vec2 position = Vec2::Zero();    // the shot's centre at impact
  ContactKind other_kind = ContactKind::kBall;
  std::uint32_t other_id = 0;      // the ball or segment it hits
};

// Where a shot will go: its centre every sample step from the muzzle, ending at its first
// impact (when one comes within the horizon).
struct ShotPrediction {
  std::vector<Vec2> path;
  std::optional<PredictedImpact> first_impact;
};

// The longest prediction, in steps: a bound on its work.
constexpr long kMaxPredictionSteps = 1000000;

// Runs the engine forward on a copy of `world` with `shot` added (a ghost ball: everything
// else moves and collides as it will), in steps of `time_step` for at most `horizon` seconds,
// until the shot's first impact. Throws std::invalid_argument as World::addBall does (e.g. the
// muzzle overlaps a ball), if time_step is not positive or if horizon is not within
// [0, kMaxPredictionSteps time steps].
ShotPrediction predictShot(const World& world, const Ball& shot, double time_step,
                           double horizon);

}  // namespace ball_physics_sim::engine
