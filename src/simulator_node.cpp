#include "ball_physics_sim/simulator_node.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <geometry_msgs/TransformStamped.h>
#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>

#include "ball_physics_sim/BallStateArray.h"
#include "ball_physics_sim/ContactArray.h"
#include "ball_physics_sim/conversions.h"
#include "ball_physics_sim/engine/aiming.h"
#include "ball_physics_sim/markers.h"

namespace ball_physics_sim {

namespace {

std::string scenePath(const ros::NodeHandle& private_nh) {
  std::string file;
  if (private_nh.getParam("scene_file", file)) return file;
  const std::string scene = private_nh.param<std::string>("scene", "default");
  return ros::package::getPath("ball_physics_sim") + "/config/scenes/" + scene + ".yaml";
}

double positiveParam(const ros::NodeHandle& private_nh, const std::string& name, double fallback,
                     bool zero_allowed = false) {
  const double value = private_nh.param(name, fallback);
  if (!std::isfinite(value) || value < 0.0 || (value == 0.0 && !zero_allowed))
    throw std::invalid_argument("~" + name + " must be " + (zero_allowed ? ">= 0" : "> 0") +
                                ", got " + std::to_string(value));
  return value;
}

// Wraps to (-pi, pi].
double normalizedAngle(double angle) { return std::atan2(std::sin(angle), std::cos(angle)); }

// Numbers in messages, in the shortest form that reads well ("9", "9.93194").
template <typename T>
std::string format(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string format(const engine::Vec2& v) { return "(" + format(v.x()) + ", " + format(v.y()) + ")"; }

geometry_msgs::TransformStamped frame(const std::string& parent, const std::string& child,
                                      const ros::Time& stamp, const engine::Vec2& position,
                                      double yaw) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = stamp;
  t.child_frame_id = child;
  t.transform.translation.x = position.x();
  t.transform.translation.y = position.y();
  t.transform.rotation.z = std::sin(0.5 * yaw);
  t.transform.rotation.w = std::cos(0.5 * yaw);
  return t;
}

}  // namespace

SimulatorNode::SimulatorNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
    : scene_(engine::loadScene(scenePath(private_nh))),
      frame_id_(private_nh.param<std::string>("frame_id", "world")),
      time_step_(positiveParam(private_nh, "time_step", 1.0 / 120.0)),
      real_time_factor_(positiveParam(private_nh, "real_time_factor", 1.0, true)),
      state_period_(1.0 / positiveParam(private_nh, "publish_rate", 60.0)),
      marker_period_(1.0 / positiveParam(private_nh, "marker_rate", 30.0)),
      fire_on_click_(private_nh.param("fire_on_click", false)),
      publish_clock_(nh.param("/use_sim_time", false)) {
  balls_pub_ = nh.advertise<BallStateArray>("balls", 10);
  contacts_pub_ = nh.advertise<ContactArray>("contacts", 100);
  markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  if (publish_clock_) clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  aim_service_ = nh.advertiseService("aim", &SimulatorNode::aim, this);
  fire_service_ = nh.advertiseService("fire", &SimulatorNode::fire, this);
  clicked_point_sub_ = nh.subscribe("clicked_point", 10, &SimulatorNode::aimAtClickedPoint, this);
  ROS_INFO("sim_node: scene '%s' with %zu balls, %zu segments, %zu launchers; step %g s",
           scene_.name.c_str(), scene_.world.balls().size(), scene_.world.segments().size(),
           scene_.launchers.size(), time_step_);
}

void SimulatorNode::run() {
  const ros::WallTime wall_start = ros::WallTime::now();
  const double sim_start = scene_.world.time();
  double next_states = sim_start, next_markers = sim_start;
  while (ros::ok()) {
    ros::spinOnce();
    step();
    const double now = scene_.world.time();
    if (now >= next_states) {
      publishStates();
      next_states += state_period_;
    }
    if (now >= next_markers) {
      publishMarkers();
      next_markers += marker_period_;
    }
    if (real_time_factor_ > 0.0) {
      const ros::WallTime due = wall_start + ros::WallDuration((now - sim_start) / real_time_factor_);
      const ros::WallTime wall_now = ros::WallTime::now();
      if (due > wall_now) (due - wall_now).sleep();
    }
  }
}

void SimulatorNode::step() {
  scene_.world.step(time_step_);
  const std::vector<engine::Contact> contacts = scene_.world.takeContacts();
  unpublished_contacts_.insert(unpublished_contacts_.end(), contacts.begin(), contacts.end());
  if (publish_clock_) {
    rosgraph_msgs::Clock clock;
    clock.clock = ros::Time(scene_.world.time());
    clock_pub_.publish(clock);
  }
}

void SimulatorNode::publishStates() {
  const ros::Time stamp(scene_.world.time());
  BallStateArray balls;
  balls.header.stamp = stamp;
  balls.header.frame_id = frame_id_;
  std::vector<geometry_msgs::TransformStamped> frames;
  for (const engine::Ball& ball : scene_.world.balls()) {
    balls.balls.push_back(toMsg(ball));
    frames.push_back(frame(frame_id_, "ball_" + std::to_string(ball.id), stamp, ball.position, 0.0));
  }
  for (const engine::Launcher& launcher : scene_.launchers)
    frames.push_back(
        frame(frame_id_, "launcher_" + launcher.name, stamp, launcher.position, launcher.angle));
  balls_pub_.publish(balls);
  tf_broadcaster_.sendTransform(frames);

  if (unpublished_contacts_.empty()) return;
  ContactArray contacts;
  contacts.header = balls.header;
  for (const engine::Contact& contact : unpublished_contacts_)
    contacts.contacts.push_back(toMsg(contact));
  contacts_pub_.publish(contacts);
  unpublished_contacts_.clear();
}

void SimulatorNode::publishMarkers() {
  markers_pub_.publish(sceneMarkers(scene_, frame_id_, ros::Time(scene_.world.time())));
}

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

namespace {

// The speed a request asks for (0: the launcher's own), or none with `error` set.
std::optional<double> requestedSpeed(double speed, const engine::Launcher& launcher,
                                     std::string& error) {
  if (speed == 0.0) return launcher.speed;
  if (!std::isfinite(speed) || speed < 0.0) {
    error = "speed must be finite and > 0 (or 0 for the launcher's " +
            format(launcher.speed) + " m/s), got " + format(speed);
    return std::nullopt;
  }
  return speed;
}

}  // namespace

bool SimulatorNode::aim(Aim::Request& request, Aim::Response& response) {
  response.success = false;
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  response.angle = launcher->angle;
  const std::optional<double> speed = requestedSpeed(request.speed, *launcher, response.message);
  if (!speed) return true;
  const engine::Vec2 target = toVec2(request.target);
  const engine::Vec2& gravity = scene_.world.gravity();

  std::optional<engine::AimSolution> solution;
  switch (request.mode) {
    case Aim::Request::ANGLE:
      if (!std::isfinite(request.angle)) {
        response.message = "angle must be finite";
        return true;
      }
      solution = engine::AimSolution{normalizedAngle(request.angle), 0.0};
      response.message = "aimed along the given angle";
      break;
    case Aim::Request::TARGET:
    case Aim::Request::TARGET_BALLISTIC: {
      if (!target.allFinite()) {
        response.message = "target must be finite";
        return true;
      }
      const bool ballistic = request.mode == Aim::Request::TARGET_BALLISTIC;
      solution = ballistic ? engine::aimBallistic(launcher->position, target, *speed, gravity,
                                                  request.high_arc)
                           : engine::aimStraight(launcher->position, target, *speed);
      if (!solution) {
        response.message =
            target == launcher->position
                ? "target " + format(target) + " is where launcher '" + launcher->name + "' is"
                : "target " + format(target) + " is out of reach at " + format(*speed) +
                      " m/s; it needs at least " +
                      format(engine::minimumBallisticSpeed(launcher->position, target, gravity)) +
                      " m/s";
        return true;
      }
      if (!ballistic && gravity != engine::Vec2::Zero()) {
        // A straight aim under gravity falls short of the target: say so, predict nothing.
        response.message = "pointed straight at the target; gravity bends the path, so use "
                           "TARGET_BALLISTIC to hit it";
        solution->time_of_flight = 0.0;
      } else {
        response.message = "aimed at " + format(target);
        response.predicted_hit = request.target;
      }
      break;
    }
    case Aim::Request::LEAD_BALL:
      response.message = "mode LEAD_BALL is not available in this version";
      return true;
    default:
      response.message = "unknown mode " + format(int(request.mode)) +
                         "; use ANGLE (0), TARGET (1) or TARGET_BALLISTIC (2)";
      return true;
  }
  launcher->angle = solution->angle;
  launcher->speed = *speed;
  response.success = true;
  response.angle = solution->angle;
  response.time_of_flight = solution->time_of_flight;
  publishMarkers();
  return true;
}

bool SimulatorNode::fire(Fire::Request& request, Fire::Response& response) {
  response.success = false;
  engine::Launcher* launcher = findLauncher(request.launcher, response.message);
  if (!launcher) return true;
  const std::optional<double> speed = requestedSpeed(request.speed, *launcher, response.message);
  if (!speed) return true;
  try {
    response.ball_id = scene_.world.addBall(launcher->launch(*speed));
  } catch (const std::invalid_argument& e) {
    response.message = "launcher '" + launcher->name + "' cannot fire: " + e.what();
    return true;
  }
  response.success = true;
  response.message = "fired ball " + std::to_string(response.ball_id) + " from '" +
                     launcher->name + "' at " + format(*speed) + " m/s";
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
