#include "ball_physics_sim/engine/prediction.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ball_physics_sim::engine {

namespace {

// A last step shorter than this fraction of a step is the rounding of horizon / time_step.
constexpr double kRoundingRemainder = 1e-9;

// The shot's impacts among a step's contacts, in order. A contact's normal points toward its
// `ball_id`, so the shot's centre lies one radius along it, or against it when the shot is
// the other ball.
std::vector<PredictedImpact> impactsOfShot(const std::vector<Contact>& contacts, BallId shot,
                                           double radius, double fired_at) {
  std::vector<PredictedImpact> impacts;
  for (const Contact& contact : contacts) {
    if (contact.ball_id == shot)
      impacts.push_back({contact.time - fired_at, contact.point + radius * contact.normal,
                         contact.point, contact.other_kind, contact.other_id});
    else if (contact.other_kind == ContactKind::kBall && contact.other_id == shot)
      impacts.push_back({contact.time - fired_at, contact.point - radius * contact.normal,
                         contact.point, ContactKind::kBall, contact.ball_id});
  }
  return impacts;
}

// Takes a step's impacts into the prediction: bounces while they are allowed, then the final
// one. True once the prediction has ended.
bool recordImpacts(const std::vector<PredictedImpact>& impacts, int bounces,
                   ShotPrediction& prediction) {
  for (const PredictedImpact& impact : impacts) {
    prediction.path.push_back(impact.position);
    if (impact.other_kind == ContactKind::kBall ||
        prediction.bounces.size() == static_cast<std::size_t>(bounces)) {
      prediction.final_impact = impact;
      return true;
    }
    prediction.bounces.push_back(impact);
  }
  return false;
}

}  // namespace

bool impactCovers(const World& world, const PredictedImpact& impact, double shot_radius,
                  const Vec2& point, double tolerance) {
  if ((point - impact.position).norm() <= shot_radius + tolerance) return true;
  if (impact.other_kind == ContactKind::kBall) {
    const Ball* other = world.findBall(impact.other_id);
    if (!other) return false;
    // Its centre lies beyond the touching point, on the line from the shot's centre.
    const Vec2 centre =
        impact.point + (impact.point - impact.position) * (other->radius / shot_radius);
    return (point - centre).norm() <= other->radius + tolerance;
  }
  const auto segment = std::find_if(world.segments().begin(), world.segments().end(),
                                    [&](const Segment& s) { return s.id == impact.other_id; });
  return segment != world.segments().end() &&
         (point - segment->closestPoint(point)).norm() <= 0.5 * segment->thickness + tolerance;
}

ShotPrediction predictShot(const World& world, const Ball& shot, double time_step,
                           double horizon, int bounces, bool until_strike) {
  if (!(time_step > 0.0)) throw std::invalid_argument("time step must be positive");
  if (bounces < 0) throw std::invalid_argument("bounces must be >= 0");
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
    const double step = i < steps ? time_step : last_step;
    if (until_strike)
      ghost_world.stepUntilStrike(step, ghost);
    else
      ghost_world.step(step);
    if (recordImpacts(impactsOfShot(ghost_world.takeContacts(), ghost, shot.radius, fired_at),
                      bounces, prediction))
      break;
    prediction.path.push_back(ghost_world.findBall(ghost)->position);
  }
  return prediction;
}

ShotPrediction predictLaunch(const World& world, const Launcher& launcher, double angle,
                             double speed, double time_step, double horizon, int bounces,
                             bool until_strike) {
  Launcher aimed = launcher;
  aimed.angle = angle;
  return predictShot(world, aimed.launch(speed), time_step, horizon, bounces, until_strike);
}

}  // namespace ball_physics_sim::engine
