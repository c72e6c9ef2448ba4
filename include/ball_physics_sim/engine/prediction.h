#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "ball_physics_sim/engine/launcher.h"
#include "ball_physics_sim/engine/world.h"

namespace ball_physics_sim::engine {

// What a shot hits first.
struct PredictedImpact {
  double time = 0.0;               // s after firing
  Vec2 position = Vec2::Zero();    // the shot's centre at impact
  Vec2 point = Vec2::Zero();       // where they touch
  ContactKind other_kind = ContactKind::kBall;
  std::uint32_t other_id = 0;      // the ball or segment it hits
};

// Where a shot will go: its centre every sample step from the muzzle and at each impact, ending
// at the impact that ends the prediction (when one comes within the horizon).
struct ShotPrediction {
  std::vector<Vec2> path;
  std::vector<PredictedImpact> bounces;  // off segments, in order, before the final impact
  // The first impact on a ball, or on a segment once the allowed bounces are spent.
  std::optional<PredictedImpact> final_impact;
};

// Whether `point` lies within `tolerance` of what meets at `impact`: the shot's disc, or the
// body it strikes (a ball where it is then, or a segment's capsule) in `world`, the world the
// prediction ran on (false if that body is not in it). A shot aimed at `point` that strikes
// there has arrived.
bool impactCovers(const World& world, const PredictedImpact& impact, double shot_radius,
                  const Vec2& point, double tolerance);

// The longest prediction, in steps: a bound on its work.
constexpr long kMaxPredictionSteps = 1000000;

// Runs the engine forward on a copy of `world` with `shot` added (a ghost ball: everything
// else moves and collides as it will), in steps of `time_step` for at most `horizon` seconds,
// until the shot's first impact or, with `bounces` > 0, on through that many impacts on
// segments (a bank shot) to the next. `until_strike` stops the world at the shot's strike on a
// ball (World::stepUntilStrike): a search's cheap look, which may differ from what the world
// does where the strike settles a pile. Throws std::invalid_argument as World::addBall does
// (e.g. the muzzle overlaps a ball), if time_step is not positive, if horizon is not within
// [0, kMaxPredictionSteps time steps] or if bounces < 0.
ShotPrediction predictShot(const World& world, const Ball& shot, double time_step,
                           double horizon, int bounces = 0, bool until_strike = false);

// predictShot for the ball `launcher` fires along `angle` at `speed`.
ShotPrediction predictLaunch(const World& world, const Launcher& launcher, double angle,
                             double speed, double time_step, double horizon, int bounces = 0,
                             bool until_strike = false);

}  // namespace ball_physics_sim::engine
