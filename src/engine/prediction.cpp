#include "ball_physics_sim/engine/prediction.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ball_physics_sim::engine {

namespace {

// A last step shorter than this fraction of a step is the rounding of horizon / time_step.
constexpr double kRoundingRemainder = 1e-9;

// The shot's first impact among a step's contacts. A contact's normal points toward its
// `ball_id`, so the shot's centre lies one radius along it, or against it when the shot is
// the other ball.
std::optional<PredictedImpact> impactOfShot(const std::vector<Contact>& contacts, BallId shot,
                                            double radius, double fired_at) {
  for (const Contact& contact : contacts) {
    if (contact.ball_id == shot)
      return PredictedImpact{contact.time - fired_at, contact.point + radius * contact.normal,
                             contact.other_kind, contact.other_id};
    if (contact.other_kind == ContactKind::kBall && contact.other_id == shot)
      return PredictedImpact{contact.time - fired_at, contact.point - radius * contact.normal,
                             ContactKind::kBall, contact.ball_id};
  }
  return std::nullopt;
}

const Ball& ballWithId(const World& world, BallId id) {
  return *std::find_if(world.balls().begin(), world.balls().end(),
                       [id](const Ball& ball) { return ball.id == id; });
}

}  // namespace

ShotPrediction predictShot(const World& world, const Ball& shot, double time_step,
                           double horizon) {
  if (!(time_step > 0.0)) throw std::invalid_argument("time step must be positive");
  if (!(horizon >= 0.0 && horizon <= kMaxPredictionSteps * time_step))
    throw std::invalid_argument("horizon must be within [0, " +
                                std::to_string(kMaxPredictionSteps) + " time steps]");
  World ghost_world = world;
  ghost_world.takeContacts();  // what happened before the shot is not its impact
  const BallId ghost = ghost_world.addBall(shot);
  const double fired_at = ghost_world.time();
  ShotPrediction prediction;
  prediction.path.push_back(shot.position);
  // Steps counted as integers: the world's clock rounds, and a remainder measured on it can be
  // too small to advance it. horizon / time_step may round up past a whole number; the
  // remainder step that would leave is dropped.
  auto steps = static_cast<long>(std::ceil(horizon / time_step));
  double last_step = horizon - (steps - 1) * time_step;
  if (steps > 1 && last_step <= kRoundingRemainder * time_step) {
    --steps;
    last_step = time_step;
  }
  for (long i = 1; i <= steps; ++i) {
    ghost_world.step(i < steps ? time_step : last_step);
    prediction.first_impact =
        impactOfShot(ghost_world.takeContacts(), ghost, shot.radius, fired_at);
    if (prediction.first_impact) {
      prediction.path.push_back(prediction.first_impact->position);
      break;
    }
    prediction.path.push_back(ballWithId(ghost_world, ghost).position);
  }
  return prediction;
}

}  // namespace ball_physics_sim::engine
