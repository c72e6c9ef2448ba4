// SimulatorNode: the launchers' services, aim and fire, and rviz's clicked point.

#include "ball_physics_sim/simulator_node.h"

#include <cmath>
#include <stdexcept>

#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/engine/bank_shot.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

namespace {

// What a predicted shot strikes, for messages: "segment 3 at (x, y) after t s".
std::string describe(const engine::PredictedImpact& hit) {
  const char* kind = hit.other_kind == engine::ContactKind::kBall      ? "ball "
                     : hit.other_kind == engine::ContactKind::kSegment ? "segment "
                                                                       : "the end of segment ";
  return kind + format(hit.other_id) + " at " + format(hit.position) + " after " +
         format(hit.time) + " s";
}

// Why a shot cannot be predicted (its muzzle is blocked, ...).
std::string cannotPredict(const std::invalid_argument& e) {
  return std::string("cannot predict the shot: ") + e.what();
}

// The speed a request asks for (0: the launcher's own), or none with `error` set.
std::optional<double> requestedSpeed(double speed, const engine::Launcher& launcher,
                                     double max_speed, std::string& error) {
  if (speed == 0.0) return launcher.speed;
  if (!std::isfinite(speed) || speed < 0.0 || speed > max_speed) {
    error = "speed must be finite and > 0, at most " + format(max_speed) +
            " m/s (~max_speed; or 0 for the launcher's " + format(launcher.speed) + " m/s), got " +
            format(speed);
    return std::nullopt;
  }
  return speed;
}

}  // namespace

engine::Launcher* SimulatorNode::findLauncher(const std::string& name, std::string& error) {
  if (scene_.launchers.empty()) {
    error = "scene '" + scene_.name + "' has no launcher";
    return nullptr;
  }
  if (name.empty()) return &scene_.launchers.front();
  for (engine::Launcher& launcher : scene_.launchers)
    if (launcher.name == name) return &launcher;
  error = "no launcher named '" + name + "'; the scene has:";
  for (const engine::Launcher& launcher : scene_.launchers) error += " '" + launcher.name + "'";
  return nullptr;
}

bool SimulatorNode::aim(Aim::Request& request, Aim::Response& response) {
  response.success = false;
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  response.angle = launcher->angle;
  response.speed = launcher->speed;
  std::optional<double> speed =
      requestedSpeed(request.speed, *launcher, max_speed_, response.message);
  if (!speed) return true;

  const bool angle_given =
      request.mode == Aim::Request::ANGLE || request.mode == Aim::Request::TIMED;
  if (angle_given && !std::isfinite(request.angle)) {
    response.message = "angle must be finite";
    return true;
  }
  if (request.time_of_flight != 0.0 && request.mode != Aim::Request::TARGET_BALLISTIC) {
    response.message = "time_of_flight is for TARGET_BALLISTIC only";
    return true;
  }

  std::optional<engine::AimSolution> solution;
  switch (request.mode) {
    case Aim::Request::ANGLE:
      response.message = "aimed along the given angle";
      solution = aimAlong(*launcher, engine::normalizedAngle(request.angle), *speed, response);
      break;
    case Aim::Request::TARGET:
    case Aim::Request::TARGET_BALLISTIC:
      solution = aimAtPoint(*launcher, request, *speed, response);
      break;
    case Aim::Request::LEAD_BALL:
      solution = leadBall(*launcher, *speed, request.target_ball_id, response);
      break;
    case Aim::Request::TIMED:
      solution = timeBall(*launcher, engine::normalizedAngle(request.angle), *speed,
                          request.target_ball_id, response);
      break;
    case Aim::Request::BANK:
      solution = bankBall(*launcher, *speed, request.target_ball_id, response);
      break;
    default:
      response.message = "unknown mode " + format(int(request.mode)) +
                         "; use ANGLE (0), TARGET (1), TARGET_BALLISTIC (2), LEAD_BALL (3), "
                         "TIMED (4) or BANK (5)";
      return true;
  }
  if (!solution) return true;
  launcher->angle = solution->angle;
  launcher->speed = *speed;
  if (request.mode == Aim::Request::BANK)
    banking_launchers_.insert(launcher->name);
  else
    banking_launchers_.erase(launcher->name);
  predictions_stale_ = true;
  response.success = true;
  response.angle = solution->angle;
  response.speed = *speed;
  response.time_of_flight = solution->time_of_flight;
  publishMarkers();
  return true;
}

std::optional<engine::ShotPrediction> SimulatorNode::predictAim(
    const engine::World& world, const engine::Launcher& launcher, double angle, double speed,
    double horizon, std::string& error) const {
  try {
    return engine::predictLaunch(world, launcher, angle, speed, time_step_, horizon);
  } catch (const std::invalid_argument& e) {
    error = cannotPredict(e);
    return std::nullopt;
  }
}

engine::AimSolution SimulatorNode::aimAlong(const engine::Launcher& launcher, double angle,
                                            double speed, Aim::Response& response) const {
  if (prediction_horizon_ == 0.0) return engine::AimSolution{angle, 0.0};
  std::string error;
  const std::optional<engine::ShotPrediction> prediction =
      predictAim(scene_.world, launcher, angle, speed, prediction_horizon_, error);
  if (!prediction) {
    response.message += "; " + error;  // pointing needs no prediction: the aim still holds
    return engine::AimSolution{angle, 0.0};
  }
  const std::optional<engine::PredictedImpact>& hit = prediction->final_impact;
  if (!hit) {
    response.message += "; the shot hits nothing within " + format(prediction_horizon_) +
                        " s (~prediction_horizon)";
    return engine::AimSolution{angle, 0.0};
  }
  response.message += "; the shot first hits " + describe(*hit);
  response.predicted_hit = toPoint(hit->position);
  return engine::AimSolution{angle, hit->time};
}

std::optional<engine::AimSolution> SimulatorNode::aimAtPoint(const engine::Launcher& launcher,
                                                             const Aim::Request& request,
                                                             double& speed,
                                                             Aim::Response& response) const {
  const engine::Vec2 target = toVec2(request.target);
  if (!target.allFinite()) {
    response.message = "target must be finite";
    return std::nullopt;
  }
  if (target == launcher.position) {
    response.message = "target " + format(target) + " is where launcher '" + launcher.name + "' is";
    return std::nullopt;
  }
  const engine::Vec2& gravity = scene_.world.gravity();
  const bool ballistic = request.mode == Aim::Request::TARGET_BALLISTIC;
  std::optional<engine::AimSolution> solution;
  if (ballistic && request.time_of_flight != 0.0) {
    solution = timedArc(launcher, target, request, speed, response);
  } else if (ballistic) {
    solution = engine::aimBallistic(launcher.position, target, speed, gravity, request.high_arc);
    if (!solution)
      response.message =
          "target " + format(target) + " is out of reach at " + format(speed) +
          " m/s; it needs at least " +
          format(engine::minimumBallisticSpeed(launcher.position, target, gravity)) + " m/s";
  } else {
    solution = engine::aimStraight(launcher.position, target, speed);
    if (gravity != engine::Vec2::Zero()) {
      // A straight aim under gravity falls short of the target: say so, and where it lands.
      response.message = "pointed straight at the target; gravity bends the path, so use "
                         "TARGET_BALLISTIC to hit it";
      return aimAlong(launcher, solution->angle, speed, response);
    }
  }
  if (!solution) return std::nullopt;
  return arrivalAt(launcher, *solution, speed, target, response);
}

std::optional<engine::AimSolution> SimulatorNode::timedArc(const engine::Launcher& launcher,
                                                           const engine::Vec2& target,
                                                           const Aim::Request& request,
                                                           double& speed,
                                                           Aim::Response& response) const {
  const double time_of_flight = request.time_of_flight;
  if (!std::isfinite(time_of_flight) || time_of_flight < 0.0) {
    response.message = "time_of_flight must be finite and > 0 (or 0 to aim at `speed`), got " +
                       format(time_of_flight);
    return std::nullopt;
  }
  if (request.speed != 0.0) {
    response.message = "give speed or time_of_flight, not both: the time fixes the speed";
    return std::nullopt;
  }
  const engine::Vec2 velocity = engine::launchVelocityFor(launcher.position, target,
                                                          time_of_flight, scene_.world.gravity());
  const double needed = velocity.norm();
  if (!(needed > 0.0 && needed <= max_speed_)) {
    response.message = "reaching " + format(target) + " in " + format(time_of_flight) +
                       " s needs " + format(needed) + " m/s; shots go > 0 and at most " +
                       format(max_speed_) + " m/s (~max_speed)";
    return std::nullopt;
  }
  speed = needed;
  return engine::AimSolution{std::atan2(velocity.y(), velocity.x()), time_of_flight};
}

std::optional<engine::AimSolution> SimulatorNode::arrivalAt(const engine::Launcher& launcher,
                                                            const engine::AimSolution& solution,
                                                            double speed,
                                                            const engine::Vec2& target,
                                                            Aim::Response& response) const {
  response.predicted_hit = toPoint(target);
  // The node predicts no further ahead than its markers do.
  if (prediction_horizon_ == 0.0 || solution.time_of_flight > kMaxPredictionHorizon) {
    response.message = "aimed at " + format(target) + ": the shot arrives after " +
                       format(solution.time_of_flight) + " s, unchecked for obstacles (" +
                       (prediction_horizon_ == 0.0 ? "~prediction_horizon is 0)"
                                                   : "longer than " +
                                                         format(kMaxPredictionHorizon) + " s)");
    return solution;
  }
  const std::optional<engine::ShotPrediction> prediction =
      predictAim(scene_.world, launcher, solution.angle, speed,
                 solution.time_of_flight + time_step_, response.message);
  if (!prediction) return std::nullopt;
  const std::optional<engine::PredictedImpact>& hit = prediction->final_impact;
  if (!hit || hit->time >= solution.time_of_flight) {
    response.message = "aimed at " + format(target) + ": the shot arrives after " +
                       format(solution.time_of_flight) + " s";
    return solution;
  }
  // Striking what lies at the target (a ball clicked on, the wall aimed at) is arriving; a point
  // clicked on a segment drawn thicker than it is counts as on it.
  if (!engine::impactCovers(scene_.world, *hit, launcher.projectile.radius, target,
                            0.5 * kMinDrawnThickness)) {
    response.message = "target " + format(target) + " is blocked: the shot would first hit " +
                       describe(*hit);
    return std::nullopt;
  }
  response.message = "aimed at " + format(target) + ": the shot strikes " + describe(*hit) +
                     ", at the target";
  response.predicted_hit = toPoint(hit->position);
  return engine::AimSolution{solution.angle, hit->time};
}

std::optional<engine::PredictedImpact> SimulatorNode::strikeOf(
    const engine::World& world, const engine::Launcher& launcher, double angle, double speed,
    engine::BallId target, double time_of_flight, Aim::Response& response) const {
  const std::optional<engine::ShotPrediction> prediction =
      predictAim(world, launcher, angle, speed, time_of_flight + time_step_, response.message);
  if (!prediction) return std::nullopt;
  const std::optional<engine::PredictedImpact>& hit = prediction->final_impact;
  if (!hit || hit->other_kind != engine::ContactKind::kBall || hit->other_id != target) {
    response.message =
        hit ? "the shot at ball " + format(target) + " would first hit " + describe(*hit)
            : "ball " + format(target) + " changes course (it hits something) before the shot "
              "reaches it";
    return std::nullopt;
  }
  response.predicted_hit = toPoint(hit->position);
  return hit;
}

std::optional<engine::Motion> SimulatorNode::motionOfTarget(engine::BallId target,
                                                           Aim::Response& response) const {
  const std::optional<engine::Motion> motion = scene_.world.motionOfBall(target);
  if (!motion) response.message = "there is no ball " + format(target);
  return motion;
}

std::optional<engine::AimSolution> SimulatorNode::leadBall(const engine::Launcher& launcher,
                                                           double speed, engine::BallId target,
                                                           Aim::Response& response) const {
  const std::optional<engine::Motion> motion = motionOfTarget(target, response);
  if (!motion) return std::nullopt;
  const std::optional<engine::AimSolution> solution =
      engine::aimLeading(launcher.position, speed, *motion, scene_.world.gravity());
  if (!solution) {
    response.message = "ball " + format(target) + " cannot be caught at " + format(speed) +
                       " m/s from launcher '" + launcher.name + "'";
    return std::nullopt;
  }
  const auto hit = strikeOf(scene_.world, launcher, solution->angle, speed, target,
                            solution->time_of_flight, response);
  if (!hit) return std::nullopt;
  response.message = "leading ball " + format(target) + ": it is struck after " +
                     format(hit->time) + " s";
  return engine::AimSolution{solution->angle, hit->time};
}

std::optional<engine::AimSolution> SimulatorNode::timeBall(const engine::Launcher& launcher,
                                                           double angle, double speed,
                                                           engine::BallId target,
                                                           Aim::Response& response) const {
  const std::optional<engine::Motion> motion = motionOfTarget(target, response);
  if (!motion) return std::nullopt;
  const std::optional<engine::TimedShot> shot =
      engine::timeShot(launcher.position, angle, speed, *motion, scene_.world.gravity());
  if (!shot) {
    response.message = "ball " + format(target) + " never crosses the path of launcher '" +
                       launcher.name + "' at " + format(angle) + " rad and " + format(speed) +
                       " m/s";
    return std::nullopt;
  }
  // The node fires between steps: the delay becomes whole steps, and the shot's prediction
  // starts from the world those steps make.
  if ((shot->delay + shot->time_of_flight) / time_step_ > engine::kMaxPredictionSteps) {
    response.message = "ball " + format(target) + " crosses the path only after " +
                       format(shot->delay) + " s, too far ahead to predict";
    return std::nullopt;
  }
  const long steps = std::lround(shot->delay / time_step_);
  engine::World later = scene_.world;
  for (long i = 0; i < steps; ++i) later.step(time_step_);
  const auto hit =
      strikeOf(later, launcher, angle, speed, target, shot->time_of_flight, response);
  if (!hit) return std::nullopt;
  response.fire_after = steps * time_step_;
  response.message = "fire after " + format(steps) + " steps (" + format(response.fire_after) +
                     " s; exactly " + format(shot->delay) + " s): ball " + format(target) +
                     " is struck " + format(hit->time) + " s later";
  return engine::AimSolution{angle, hit->time};
}

std::optional<engine::AimSolution> SimulatorNode::bankBall(const engine::Launcher& launcher,
                                                           double speed, engine::BallId target,
                                                           Aim::Response& response) const {
  if (!motionOfTarget(target, response)) return std::nullopt;
  if (prediction_horizon_ == 0.0) {
    response.message = "BANK searches shots with the prediction: it needs ~prediction_horizon > 0";
    return std::nullopt;
  }
  std::optional<engine::BankShot> shot;
  try {
    shot = engine::aimBank(scene_.world, launcher, speed, target, time_step_, prediction_horizon_);
  } catch (const std::invalid_argument& e) {
    response.message = cannotPredict(e);
    return std::nullopt;
  }
  if (!shot) {
    response.message = "found no shot at " + format(speed) + " m/s from launcher '" +
                       launcher.name + "' that strikes ball " + format(target) + " after 1 to " +
                       format(engine::kMaxBankBounces) + " bounces within " +
                       format(prediction_horizon_) + " s (~prediction_horizon)";
    return std::nullopt;
  }
  const engine::PredictedImpact& strike = *shot->prediction.final_impact;
  response.message = "bank shot:";
  for (const engine::PredictedImpact& bounce : shot->prediction.bounces)
    response.message += " off " + describe(bounce) + ", then";
  response.message += " strikes " + describe(strike);
  response.predicted_hit = toPoint(strike.position);
  return engine::AimSolution{shot->angle, strike.time};
}

bool SimulatorNode::fire(Fire::Request& request, Fire::Response& response) {
  response.success = false;
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  const std::optional<double> speed =
      requestedSpeed(request.speed, *launcher, max_speed_, response.message);
  if (!speed) return true;
  std::string error;
  response.ball_id = addBall(launcher->launch(*speed), error);
  if (response.ball_id == 0) {
    response.message = "launcher '" + launcher->name + "' cannot fire: " + error;
    return true;
  }
  response.success = true;
  response.message = "fired ball " + format(response.ball_id) + " from '" + launcher->name +
                     "' at " + format(*speed) + " m/s";
  return true;
}

void SimulatorNode::aimAtClickedPoint(const geometry_msgs::PointStamped& point) {
  if (!point.header.frame_id.empty() && point.header.frame_id != frame_id_) {
    ROS_WARN("clicked_point in frame '%s' ignored: points must be in '%s'",
             point.header.frame_id.c_str(), frame_id_.c_str());
    return;
  }
  Aim::Request aim_request;
  Aim::Response aim_response;
  aim_request.mode = Aim::Request::TARGET_BALLISTIC;
  aim_request.target = point.point;
  aim(aim_request, aim_response);
  ROS_INFO("clicked_point: %s", aim_response.message.c_str());
  if (!aim_response.success || !fire_on_click_) return;
  Fire::Request fire_request;
  Fire::Response fire_response;
  fire(fire_request, fire_response);
  ROS_INFO("clicked_point: %s", fire_response.message.c_str());
}

}  // namespace ball_physics_sim
