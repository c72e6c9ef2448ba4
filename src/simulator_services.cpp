// SimulatorNode: the services that change the world: balls, segments, blasts, drives, the
// scene, reset, pause and step (as flatland's service_manager).

#include "ball_physics_sim/simulator_node.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

namespace {

// One `step` call runs this many steps at most: the node answers nothing else meanwhile.
constexpr std::uint32_t kMaxStepsPerCall = 100000;

}  // namespace

std::optional<std::string> SimulatorNode::refusal(const engine::Ball& ball) {
  if (scene_.world.balls().size() >= max_balls_)
    return "the world is full: " + format(max_balls_) + " balls (~max_balls)";
  try {
    engine::checkBall(ball);  // what no ball can be (NaN, ...) before what this node allows
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  if (ball.radius > max_radius_)
    return "radius must be at most " + format(max_radius_) + " m (~max_radius), got " +
           format(ball.radius);
  if (std::optional<std::string> why = speedRefusal(ball.velocity)) return why;
  // A token bucket: up to a second's worth of balls at once, then ~max_spawn_rate per second.
  const ros::WallTime now = ros::WallTime::now();
  spawn_allowance_ = std::min(std::max(max_spawn_rate_, 1.0),
                              spawn_allowance_ + (now - last_spawn_).toSec() * max_spawn_rate_);
  last_spawn_ = now;
  if (spawn_allowance_ < 1.0)
    return "too many new balls: at most " + format(max_spawn_rate_) +
           " per second (~max_spawn_rate)";
  return std::nullopt;
}

std::optional<std::string> SimulatorNode::speedRefusal(const engine::Vec2& velocity) const {
  // A non-finite velocity is left to the engine, whose refusal says so.
  if (velocity.allFinite() && velocity.norm() > max_speed_)
    return "speed must be at most " + format(max_speed_) + " m/s (~max_speed), got " +
           format(velocity.norm());
  return std::nullopt;
}

engine::BallId SimulatorNode::addBall(const engine::Ball& ball, std::string& error) {
  if (const std::optional<std::string> why = refusal(ball)) {
    error = *why;
    return 0;
  }
  try {
    const engine::BallId id = scene_.world.addBall(ball);
    predictions_stale_ = true;
    spawn_allowance_ -= 1.0;
    return id;
  } catch (const std::invalid_argument& e) {
    error = e.what();
    return 0;
  }
}

bool SimulatorNode::spawnBall(SpawnBall::Request& request, SpawnBall::Response& response) {
  std::string error;
  response.ball_id = addBall(toBall(request), error);
  response.success = response.ball_id != 0;
  response.message = response.success ? "spawned ball " + format(response.ball_id)
                                      : "cannot spawn the ball: " + error;
  return true;
}

bool SimulatorNode::removeBall(RemoveBall::Request& request, RemoveBall::Response& response) {
  response.success = scene_.world.removeBall(request.ball_id);
  predictions_stale_ = true;
  response.message = (response.success ? "removed ball " : "there is no ball ") +
                     format(request.ball_id);
  return true;
}

bool SimulatorNode::setBallState(SetBallState::Request& request,
                                 SetBallState::Response& response) {
  response.success = false;
  const std::string cannot = "cannot set the state of ball " + format(request.ball_id) + ": ";
  const engine::Vec2 position = toVec2(request.position), velocity = toVec2(request.velocity);
  if (const std::optional<std::string> why = speedRefusal(velocity)) {
    response.message = cannot + *why;
    return true;
  }
  try {
    if (!scene_.world.setBallState(request.ball_id, position, velocity, request.angular_velocity)) {
      response.message = "there is no ball " + format(request.ball_id);
      return true;
    }
  } catch (const std::invalid_argument& e) {
    response.message = cannot + e.what();
    return true;
  }
  predictions_stale_ = true;
  response.success = true;
  response.message = "ball " + format(request.ball_id) + " is at " + format(position) +
                     " moving at " + format(velocity) + " m/s, " +
                     format(request.angular_velocity) + " rad/s";
  return true;
}

bool SimulatorNode::explode(Explode::Request& request, Explode::Response& response) {
  response.success = false;
  try {
    response.ball_ids = scene_.world.explode(toBlast(request), max_speed_);
  } catch (const std::invalid_argument& e) {
    response.message = std::string("cannot explode: ") + e.what();
    return true;
  }
  predictions_stale_ = true;
  response.success = true;
  response.message = "the blast pushed " + format(response.ball_ids.size()) + " balls";
  return true;
}

void SimulatorNode::driveBall(const geometry_msgs::Twist& twist) {
  const std::vector<engine::Ball>& balls = scene_.world.balls();
  if (driven_ball_ == 0 && balls.empty()) {
    ROS_WARN_THROTTLE(1.0, "cmd_vel ignored: there is no ball to drive");
    return;
  }
  const engine::BallId id = driven_ball_ != 0 ? driven_ball_ : balls.back().id;
  // A command refused leaves the drive on as it was, and its timeout with it.
  try {
    if (!scene_.world.drive(id, engine::Vec2(twist.linear.x, twist.linear.y))) {
      ROS_WARN_THROTTLE(1.0, "cmd_vel ignored: there is no ball %u to drive (~driven_ball)", id);
      return;
    }
  } catch (const std::invalid_argument& e) {
    ROS_WARN_THROTTLE(1.0, "cmd_vel ignored: %s", e.what());
    return;
  }
  if (driving_ && *driving_ != id) scene_.world.drive(*driving_, engine::Vec2::Zero());
  predictions_stale_ = true;
  driving_ = id;
  drive_until_ = scene_.world.time() + cmd_vel_timeout_;
}

bool SimulatorNode::addSegment(AddSegment::Request& request, AddSegment::Response& response) {
  response.success = false;
  if (scene_.world.segments().size() >= max_segments_) {
    response.message = "cannot add the segment: the world has its most segments, " +
                       format(max_segments_) + " (~max_segments)";
    return true;
  }
  try {
    response.segment_id = scene_.world.addSegment(toSegment(request));
    predictions_stale_ = true;
  } catch (const std::invalid_argument& e) {
    response.message = std::string("cannot add the segment: ") + e.what();
    return true;
  }
  response.success = true;
  response.message = "added segment " + format(response.segment_id);
  return true;
}

bool SimulatorNode::removeSegment(RemoveSegment::Request& request,
                                  RemoveSegment::Response& response) {
  response.success = scene_.world.removeSegment(request.segment_id);
  predictions_stale_ = true;
  response.message = (response.success ? "removed segment " : "there is no segment ") +
                     format(request.segment_id);
  return true;
}

bool SimulatorNode::setSegmentMotion(SetSegmentMotion::Request& request,
                                     SetSegmentMotion::Response& response) {
  response.success = false;
  try {
    if (!scene_.world.setSegmentMotion(request.segment_id, toVec2(request.velocity),
                                       request.angular_velocity)) {
      response.message = "there is no segment " + format(request.segment_id);
      return true;
    }
  } catch (const std::invalid_argument& e) {
    response.message = std::string("cannot move the segment: ") + e.what();
    return true;
  }
  predictions_stale_ = true;
  response.success = true;
  response.message = "segment " + format(request.segment_id) + " moves at (" +
                     format(request.velocity.x) + ", " + format(request.velocity.y) + ") m/s, " +
                     format(request.angular_velocity) + " rad/s";
  return true;
}

bool SimulatorNode::loadScene(LoadScene::Request& request, LoadScene::Response& response) {
  response.success = false;
  const int ways = !request.name.empty() + !request.file.empty() + !request.yaml.empty();
  if (ways != 1) {
    response.message = "give exactly one of name, file and yaml; got " + format(ways);
    return true;
  }
  // Read whole before anything changes: a bad scene leaves the running one as it was.
  std::optional<engine::Scene> loaded;
  try {
    loaded = request.yaml.empty() ? engine::loadScene(request.name.empty()
                                                          ? request.file
                                                          : shippedScenePath(request.name))
                                  : engine::parseScene(request.yaml, "yaml");
  } catch (const engine::SceneError& e) {
    response.message = std::string("cannot load the scene: ") + e.what();
    return true;
  }
  // The node's limits hold for a whole scene as for bodies added one by one.
  for (const auto& [count, most, bodies] :
       {std::tuple{loaded->world.balls().size(), max_balls_, "balls (~max_balls)"},
        std::tuple{loaded->world.segments().size(), max_segments_, "segments (~max_segments)"}})
    if (count > most) {
      response.message = "cannot load the scene: it has " + format(count) + ", more than " +
                         format(most) + " " + bodies;
      return true;
    }
  initial_scene_ = std::move(*loaded);
  restartScene();
  predictions_.clear();  // the old launchers', one per launcher: markers must not pair them anew
  // Ids and launchers of the old scene may come again in the new one.
  forgetDrawnMarkers();
  response.success = true;
  response.message = "loaded scene '" + scene_.name + "': " + format(scene_.world.balls().size()) +
                     " balls, " + format(scene_.world.segments().size()) + " segments, " +
                     format(scene_.launchers.size()) + " launchers; sim time 0";
  return true;
}

void SimulatorNode::restartScene() {
  scene_ = initial_scene_;
  ++worlds_changed_;
  banking_launchers_.clear();
  driving_.reset();
  predictions_stale_ = true;
  unpublished_contacts_.clear();
  restartPacing();
  // Time jumps back: /clock says so (tf listeners clear their buffers) and tf starts again.
  publishClock();
  last_tf_stamp_.reset();
  publishConfigInForce();  // the scene's gravity
}

bool SimulatorNode::reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  restartScene();
  response.success = true;
  response.message = "scene '" + scene_.name + "' is back at its initial state, sim time 0";
  return true;
}

bool SimulatorNode::pause(std_srvs::SetBool::Request& request,
                          std_srvs::SetBool::Response& response) {
  paused_ = request.data;
  restartPacing();
  response.success = true;
  response.message = (paused_ ? "paused at sim time " : "running from sim time ") +
                     format(scene_.world.time());
  return true;
}

bool SimulatorNode::step(Step::Request& request, Step::Response& response) {
  response.success = false;
  response.time = scene_.world.time();
  if (!paused_) {
    response.message = "the simulation is running; pause it first (pause: true)";
    return true;
  }
  if (request.steps == 0 || request.steps > kMaxStepsPerCall) {
    response.message = "steps must be within [1, " + format(kMaxStepsPerCall) + "], got " +
                       format(request.steps);
    return true;
  }
  for (std::uint32_t i = 0; i < request.steps; ++i) stepOnce();
  response.success = true;
  response.time = scene_.world.time();
  response.message = "stepped " + format(request.steps) + " x " + format(time_step_) +
                     " s to sim time " + format(response.time);
  return true;
}

}  // namespace ball_physics_sim
