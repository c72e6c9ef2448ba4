// SimulatorNode: the launchers' services, aim and fire, and rviz's clicked point.

#include "ball_physics_sim/simulator_node.h"

#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/engine/aim_request.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

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

engine::AimLimits SimulatorNode::aimLimits() const {
  // A point clicked on a segment drawn thicker than it is counts as on it.
  return {time_step_, live_.prediction_horizon, max_speed_, 0.5 * kMinDrawnThickness};
}

bool SimulatorNode::aim(Aim::Request& request, Aim::Response& response) {
  // Answered on the aim queue's own thread: the shot is predicted on a copy of the world taken
  // between steps, however long that takes, while the loop steps on and publishes.
  yieldToTheLoop("sim_aim");
  std::unique_lock<std::mutex> lock = lockAgainstTheLoop();
  response.success = false;
  const engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  const engine::Launcher aimed = *launcher;
  const engine::World world = scene_.world;
  const engine::AimLimits limits = aimLimits();
  const std::uint64_t worlds_changed = worlds_changed_;
  lock.unlock();
  const engine::AimAnswer answer =
      engine::aimLauncher(world, aimed, toAimRequest(request), limits);
  lock = lockAgainstTheLoop();
  if (worlds_changed_ != worlds_changed) {
    response.message = "the scene restarted or its gravity changed while the aim was worked "
                       "out: aim again";
    return true;
  }
  takeAim(request, answer, scene_.world.time() - world.time(), response);
  return true;
}

std::unique_lock<std::mutex> SimulatorNode::lockAgainstTheLoop() {
  aim_waiting_ = true;
  std::unique_lock<std::mutex> lock(world_mutex_);
  aim_waiting_ = false;
  return lock;
}

void SimulatorNode::aimInLoop(const Aim::Request& request, Aim::Response& response) {
  response.success = false;
  const engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return;
  takeAim(request, engine::aimLauncher(scene_.world, *launcher, toAimRequest(request), aimLimits()),
          0.0, response);
}

void SimulatorNode::takeAim(const Aim::Request& request, const engine::AimAnswer& answer,
                            double elapsed, Aim::Response& response) {
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return;
  response.angle = launcher->angle;
  response.speed = launcher->speed;
  response.message = answer.message;
  if (answer.predicted_hit) response.predicted_hit = toPoint(*answer.predicted_hit);
  if (!answer.solution) return;
  // A timed shot waits from the call's answer, not from the world the aim was found on.
  const double fire_after = answer.fire_after - elapsed;
  if (request.mode == Aim::Request::TIMED && fire_after < -0.5 * time_step_) {
    response.message = "the moment to fire passed " + format(-fire_after) +
                       " s ago, while the aim was worked out: " + answer.message;
    return;
  }
  launcher->angle = answer.solution->angle;
  launcher->speed = answer.speed;
  if (request.mode == Aim::Request::BANK)
    banking_launchers_.insert(launcher->name);
  else
    banking_launchers_.erase(launcher->name);
  predictions_stale_ = true;
  response.success = true;
  response.angle = answer.solution->angle;
  response.speed = answer.speed;
  response.time_of_flight = answer.solution->time_of_flight;
  if (request.mode != Aim::Request::TIMED) return;
  response.fire_after = std::max(0.0, fire_after);
  if (elapsed > 0.0)
    response.message += "; " + format(elapsed) + " s of it passed while the aim was worked out";
}

bool SimulatorNode::fire(Fire::Request& request, Fire::Response& response) {
  response.success = false;
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  const std::optional<double> speed =
      engine::shotSpeed(request.speed, *launcher, max_speed_, response.message);
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
  aimInLoop(aim_request, aim_response);
  ROS_INFO("clicked_point: %s", aim_response.message.c_str());
  if (!aim_response.success || !live_.fire_on_click) return;
  Fire::Request fire_request;
  Fire::Response fire_response;
  fire(fire_request, fire_response);
  ROS_INFO("clicked_point: %s", fire_response.message.c_str());
}

}  // namespace ball_physics_sim
